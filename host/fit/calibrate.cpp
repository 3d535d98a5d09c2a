#include "host/fit/calibrate.hpp"

#include "host/config/model_keys.hpp"


#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace dem {

// ---------------------------------------------------------------------------------------------------
// Search

std::vector<std::string> CalibrationResult::at_edge() const {
  std::vector<std::string> out;
  for (std::size_t k = 0; k < free.size(); ++k)
    if (((best.u[k] < 0.01 && free[k].lo > 0) || best.u[k] > 0.99) &&
        std::find(searched_beyond.begin(), searched_beyond.end(), free[k].name) == searched_beyond.end())
      out.push_back(free[k].name);
  return out;
}

Real chi2_95(int d) {
  static const Real q[] = {3.841, 5.991, 7.815, 9.488};
  if (d >= 1 && d <= 4) return q[d - 1];
  return chi2_quantile(d, 1.645);
}

namespace {

/// The chi2 the surfaces give at u: the sum of their squares.
Real surfaces_chi2(const std::vector<QuadraticSurface>& s, const std::vector<Real>& u) {
  Real c = 0;
  for (const QuadraticSurface& q : s) c += q(u) * q(u);
  return c;
}

/// One search over fixed ranges: every point run is kept in `res.design`, the best in `res.best`.
class Search {
 public:
  /// `known_best`: the best chi2 of an earlier search (a widened one's), the screening's bound until one is run here.
  /// `one`: one specimen a point (OneSpecimenSearch), or null for the ensemble's search.
  Search(const Simulator& simulate, const Model& base, const std::vector<FreeParam>& free, int data, Real known_best,
         const OneSpecimenSearch* one = nullptr)
      : simulate_(simulate), base_(base), free_(free), d_(static_cast<int>(free.size())), known_best_(known_best),
        one_(one) {
    res.free = free;
    res.data = data;
    res.surrogate_answer = one != nullptr;
  }
  Model model_at(const std::vector<Real>& u) const {
    Model m = base_;
    for (int k = 0; k < d_; ++k) set_param(m, free_[k].name, free_[k].value(u[k]));
    return m;
  }
  /// The 3^d design: each parameter at the ends and the middle of its range, the centre first. Every point is
  /// probed on the simulator's first part (kProbe) before any is run whole: the best probe bounds the screening of
  /// all, where the centre alone, often far from the optimum, bounded little.
  void design() {
    long points = 1;
    for (int k = 0; k < d_; ++k) points *= 3;
    const long centre = (points - 1) / 2;  // every digit 1 in base 3
    std::vector<std::vector<Real>> us;
    for (long i = 0; i < points; ++i) {
      const long p = i == 0 ? centre : i <= centre ? i - 1 : i;
      std::vector<Real> u(d_);
      long c = p;
      for (int k = 0; k < d_; ++k, c /= 3) u[k] = 0.5 * static_cast<Real>(c % 3);
      us.push_back(u);
    }
    if (one_) {
      one_specimen_design(us);
      return;
    }
    std::vector<char> whole(us.size(), 0);
    for (std::size_t i = 0; i < us.size(); ++i) {
      SimulatedPoint s = simulate_(model_at(us[i]), kProbe);
      probe_best_ = std::min(probe_best_, sum_sq(s.r));
      if (!s.screened) {  // a simulator without parts ran it whole
        record(us[i], std::move(s));
        whole[i] = 1;
      }
    }
    for (std::size_t i = 0; i < us.size(); ++i)
      if (!whole[i]) evaluate(us[i]);
  }
  /// Up to `rounds` surrogate steps, until one points at a point already run or stops improving by 2%.
  void surrogate_rounds(int rounds) {
    for (int round = 0; round < rounds && d_ > 0; ++round) {
      const Real before = res.best.chi2;
      if (!surrogate_step()) break;  // the surface points at a point already run: converged
      if (round > 0 && res.best.chi2 > 0.98 * before) break;  // stopped improving
    }
  }
  /// A compass search around the best point in steps of 1/4, then 1/8, of each range (a valley the quadratic
  /// surfaces miss), and a last surrogate step where it moved.
  /// It moves on a significant gain only (significant_gain).
  void compass() {
    if (d_ == 0) return;
    bool moved = false;
    std::vector<Real> from = res.best.u;
    Real at = res.best.chi2;
    for (Real step : {0.25, 0.125}) {
      for (bool better = true; better;) {
        better = false;
        for (int k = 0; k < d_ && !better; ++k)
          for (Real sign : {-1.0, 1.0}) {
            std::vector<Real> u = from;
            u[k] += sign * step;
            if (u[k] < -1e-9 || u[k] > 1 + 1e-9 || run_before(u)) continue;
            const Real chi2 = evaluate(u);
            if (chi2 < at - significant_gain(at, res.data, d_)) {
              from = u;
              at = chi2;
              better = moved = true;
              break;
            }
          }
      }
    }
    if (moved) surrogate_step();
  }
  /// One specimen a point: rounds that run the surfaces' minimum on the next specimen until it and the joint region's
  /// half-widths move by less than a tenth of those half-widths, then the answer at the surfaces' minimum.
  void one_specimen_rounds() {
    if (d_ == 0) return;
    std::vector<Real> centre(d_, 0.5), was_at, was_wide;
    for (int round = 0;; ++round) {
      const std::vector<QuadraticSurface> s = response_surfaces(res.design, centre);
      auto chi2 = [&](const std::vector<Real>& x) { return surfaces_chi2(s, x); };
      const std::vector<Real> u = minimise_unit_box(chi2, d_);
      const Real scale = std::max(Real(1), chi2(u) / std::max(1, res.data - d_));
      const std::vector<Real> wide = region_half_widths(s, u, chi2_95(d_) * scale);
      bool settled = !was_at.empty();
      for (int k = 0; k < d_ && settled; ++k)
        settled = std::fabs(u[k] - was_at[k]) < 0.1 * was_wide[k] && std::fabs(wide[k] - was_wide[k]) < 0.1 * was_wide[k];
      centre = u;
      if (settled || round == one_->rounds) break;
      evaluate(u);
      was_at = u;
      was_wide = wide;
    }
    // The answer: the surfaces' minimum, centred on itself; its curves the nearest run's (one specimen's) until the
    // job runs the scatter specimens there.
    Evaluation best;
    const std::vector<QuadraticSurface> last = response_surfaces(res.design, centre);
    best.u = minimise_unit_box([&](const std::vector<Real>& x) { return surfaces_chi2(last, x); }, d_);
    Real nearest = std::numeric_limits<Real>::infinity();
    for (const Evaluation& e : res.design) {
      Real d2 = 0;
      for (int k = 0; k < d_; ++k) d2 += (e.u[k] - best.u[k]) * (e.u[k] - best.u[k]);
      if (d2 < nearest) nearest = d2, best.sim = e.sim;
    }
    for (const QuadraticSurface& q : response_surfaces(res.design, best.u)) best.r.push_back(q(best.u));
    best.chi2 = sum_sq(best.r);
    res.best = best;
  }
  CalibrationResult res;

 private:
  /// The scatter runs at the base model (where it lies inside the ranges), then the 3^d design, each point on the next
  /// specimen (the simulator's turn); a design point at the base is not run again.
  void one_specimen_design(const std::vector<std::vector<Real>>& us) {
    std::vector<Real> at(d_);
    bool inside = true;
    for (int k = 0; k < d_; ++k) {
      const Real v = get_param(base_, free_[k].name);
      inside = inside && v >= free_[k].lo && v <= free_[k].hi;
      if (inside) at[k] = free_[k].unit(v);
    }
    // A widened search has them from the first (merge_searches).
    if (inside && !std::isfinite(known_best_))
      for (const SimulatedPoint& p : one_->at_base) record(at, p);
    for (const std::vector<Real>& u : us)
      if (!run_before(u)) evaluate(u);
  }
  bool run_before(const std::vector<Real>& u) const {
    for (const Evaluation& e : res.design) {
      Real d2 = 0;
      for (int k = 0; k < d_; ++k) d2 += (e.u[k] - u[k]) * (e.u[k] - u[k]);
      if (d2 < 1e-6) return true;
    }
    return false;
  }
  /// Runs u (screened against the best so far, the probes' included); its chi2.
  Real evaluate(const std::vector<Real>& u) {
    const Real best = std::min(probe_best_, res.design.empty() ? known_best_ : std::min(known_best_, res.best.chi2));
    return record(u, simulate_(model_at(u), std::isfinite(best) ? screen_bound(best, res.data, d_)
                                                                : std::numeric_limits<Real>::infinity()));
  }
  /// Keeps the point u simulated as s in the design, and as the best where it is; its chi2.
  Real record(const std::vector<Real>& u, SimulatedPoint s) {
    Evaluation e;
    e.u = u;
    e.sim = std::move(s.sim);
    e.r = std::move(s.r);
    e.chi2 = sum_sq(e.r);
    e.screened = s.screened;
    e.specimen = s.specimen;
    res.design.push_back(e);
    if (res.design.size() == 1 || (!e.screened && (res.best.screened || e.chi2 < res.best.chi2))) res.best = e;
    return e.chi2;
  }
  /// Runs the surrogate's optimum, the surfaces centred on the best run; false when that point was run before.
  bool surrogate_step() {
    const std::vector<QuadraticSurface> s = response_surfaces(res.design, res.best.u);
    const std::vector<Real> u = minimise_unit_box([&](const std::vector<Real>& x) { return surfaces_chi2(s, x); }, d_);
    if (run_before(u)) return false;
    evaluate(u);
    return true;
  }
  const Simulator& simulate_;
  const Model& base_;
  const std::vector<FreeParam>& free_;
  int d_;
  Real known_best_;
  const OneSpecimenSearch* one_;
  /// The least chi2 of the design's probes: one member's, above the ensemble mean's by the members' spread on
  /// average.
  Real probe_best_ = std::numeric_limits<Real>::infinity();
};

/// The least chi2 of the design's points whose coordinate k lies inside its range (not on an edge).
Real best_inside(const CalibrationResult& r, std::size_t k) {
  Real best = std::numeric_limits<Real>::infinity();
  for (const Evaluation& e : r.design)
    if (!e.screened && e.u[k] >= 0.01 && e.u[k] <= 0.99) best = std::min(best, e.chi2);
  return best;
}

/// One specimen a point: the surfaces' least chi2 with coordinate k an eighth of its range or more inside the edge its
/// minimum lies on (the ensemble's compass's finest step). A run's chi2 carries its specimen's scatter, so the surfaces
/// stand for the best inside: on Table 6's S-1 (three peaks, mu_s and mu_r in one valley) a minimum on mu_r's edge
/// widened the range twice, 90 runs, and found no better point.
Real surfaces_inside(const CalibrationResult& r, std::size_t k) {
  const std::vector<QuadraticSurface> s = response_surfaces(r.design, r.best.u);
  const bool upper = r.best.u[k] > 0.5;
  auto chi2 = [&](std::vector<Real> x) {
    x[k] = upper ? 0.875 * x[k] : 0.125 + 0.875 * x[k];
    return surfaces_chi2(s, x);
  };
  return chi2(minimise_unit_box(chi2, static_cast<int>(r.best.u.size())));
}

/// `into` over the union of its ranges and `other`'s, holding both searches' points (other's first where
/// `other_first`, so that the design keeps the order the points ran in): every point's unit coordinates
/// (and the best's) mapped from its own search's ranges to the union's. The uncertainty is then computed over every
/// point run and every range searched: from the last widened range alone, a mu_r interval read [0.06, 0.12] where the
/// first range held the truth, 0.042, and the region could not reach it (coverage case 5, four times the balls).
void merge_searches(CalibrationResult& into, const CalibrationResult& other, bool other_first) {
  std::vector<FreeParam> all = into.free;
  for (std::size_t k = 0; k < all.size(); ++k) {
    all[k].lo = std::min(all[k].lo, other.free[k].lo);
    all[k].hi = std::max(all[k].hi, other.free[k].hi);
  }
  auto remap = [&](Evaluation& e, const std::vector<FreeParam>& from) {
    for (std::size_t k = 0; k < all.size(); ++k) e.u[k] = std::clamp(all[k].unit(from[k].value(e.u[k])), Real(0), Real(1));
  };
  for (Evaluation& e : into.design) remap(e, into.free);
  remap(into.best, into.free);
  std::vector<Evaluation> more = other.design;
  for (Evaluation& e : more) remap(e, other.free);
  into.design.insert(other_first ? into.design.begin() : into.design.end(), more.begin(), more.end());
  into.free = all;
}

CalibrationResult search(const Simulator& simulate, const Model& base, const std::vector<FreeParam>& free, int data,
                         int rounds, int widen, Real known_best = std::numeric_limits<Real>::infinity(),
                         const OneSpecimenSearch* one = nullptr) {
  const int d = static_cast<int>(free.size());
  Search sr(simulate, base, free, data, known_best, one);
  sr.design();
  if (one) {
    sr.one_specimen_rounds();
  } else {
    sr.surrogate_rounds(rounds);
    sr.compass();
  }
  CalibrationResult res = std::move(sr.res);
  res.model = sr.model_at(res.best.u);
  for (int k = 0; k < d; ++k) res.values.push_back(free[k].value(res.best.u[k]));
  if (widen <= 0) return res;
  // A best value on an edge of its range: the range moved to centre it, and searched again.
  std::vector<FreeParam> moved = free;
  std::vector<std::string> notes;
  bool any_moved = false;
  for (int k = 0; k < d; ++k) {
    if (res.best.u[k] >= 0.01 && res.best.u[k] <= 0.99) continue;
    const auto at = static_cast<std::size_t>(k);
    const Real inside = one ? surfaces_inside(res, at) : best_inside(res, at);
    if (res.best.chi2 > inside - significant_gain(inside, data, d)) {
      char line[200];
      std::snprintf(line, sizeof line, "%s: best %.4g on the edge of [%.4g, %.4g], chi2 %.2f against %.2f inside: "
                    "no significant gain, the range kept", free[k].name.c_str(), free[k].shown * res.values[k],
                    free[k].shown * free[k].lo, free[k].shown * free[k].hi, res.best.chi2, inside);
      notes.push_back(line);
      continue;
    }
    if (!recentre(moved[k], res.values[k])) continue;
    any_moved = true;
    char line[160];
    std::snprintf(line, sizeof line, "%s: best %.4g on the edge of [%.4g, %.4g]; searched again over [%.4g, %.4g]",
                  free[k].name.c_str(), free[k].shown * res.values[k], free[k].shown * free[k].lo,
                  free[k].shown * free[k].hi, moved[k].shown * moved[k].lo, moved[k].shown * moved[k].hi);
    notes.push_back(line);
  }
  if (!any_moved) {
    res.widened.insert(res.widened.begin(), notes.begin(), notes.end());
    return res;
  }
  CalibrationResult again = search(simulate, base, moved, data, rounds, widen - 1, res.best.chi2, one);
  if (again.best.chi2 >= res.best.chi2) {
    notes.push_back("the wider search found no better point");
    for (int k = 0; k < d; ++k)
      if (moved[k].lo != free[k].lo || moved[k].hi != free[k].hi) res.searched_beyond.push_back(free[k].name);
  }
  CalibrationResult& out = again.best.chi2 < res.best.chi2 ? again : res;
  merge_searches(out, &out == &again ? res : again, &out == &again);  // the first search's points first
  out.widened.insert(out.widened.begin(), notes.begin(), notes.end());
  return out;
}

}  // namespace

long planned_points(int d, int rounds) {
  long design = 1;
  for (int k = 0; k < d; ++k) design *= 3;
  return design + rounds + (d > 0 ? 4 * d + 1 : 0);  // the compass: both steps' polls once, and its last round
}

long planned_one_specimen_points(int d, int rounds) {
  long design = 1;
  for (int k = 0; k < d; ++k) design *= 3;
  return design + (d > 0 ? rounds : 0);
}

CalibrationResult calibrate(const Simulator& simulate, const Model& base, const std::vector<FreeParam>& free, int data,
                            int rounds, int widen) {
  CalibrationResult r = search(simulate, base, free, data, rounds, widen);
  add_uncertainty(r);
  return r;
}

CalibrationResult calibrate(const Simulator& simulate, const Model& base, const std::vector<FreeParam>& free, int data,
                            const OneSpecimenSearch& one, int widen) {
  CalibrationResult r = search(simulate, base, free, data, 0, widen, std::numeric_limits<Real>::infinity(), &one);
  add_uncertainty(r);
  return r;
}

}  // namespace dem
