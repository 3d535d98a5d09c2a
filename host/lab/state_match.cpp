/// The state match (state_match.hpp, MatchPlan): the preparation friction that packs a lab's specimens to the
/// data's void ratio, by bisection over packings that the run store may keep.
#include "host/lab/state_match.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>

#include "host/util/fnv1a.hpp"
#include "host/util/forked_runs.hpp"
#include "host/lab/periodic_lab.hpp"
#include "host/util/progress.hpp"
#include "host/lab/run_store.hpp"
#include "host/lab/wall_layer.hpp"

namespace dem {

namespace {
/// A specimen's void ratio as the plan matches it: the whole cell's, or a walled cell's at the data's size.
Real matched_void_ratio(const PackedCell& s, const MatchPlan& plan) {
  return std::isfinite(plan.data_balls) ? void_ratio_at_size(s.balls, s.cell, plan.data_balls) : s.void_ratio;
}

/// The plan's specimens' mean void ratio after their preparation, summed in seed order: packed as a lab packs
/// its specimens, so that the mean matched is the mean of a lab's first specimens, bit for bit.
Real prepared_void_ratio(const Config& cfg, const MatchPlan& plan) {
  const int n = std::max(plan.specimens, 1);
  Real sum = 0;
  if (plan.stored_only) {  // the same void ratios a lab would read from the store, summed in the same order
    Config c = larger_cell(cfg, plan.cell_factor);
    for (int k = 0; k < n; ++k) {
      c.run.seed = plan.first_seed + static_cast<unsigned>(k);
      PackedCell s;
      if (!read_packing(c, s)) throw NotPacked("no stored packing for seed " + std::to_string(c.run.seed));
      sum += matched_void_ratio(s, plan);
    }
    return sum / static_cast<Real>(n);
  }
  const PeriodicLab lab(larger_cell(cfg, plan.cell_factor), false, n, plan.first_seed, n, plan.workers);
  for (int k = 0; k < n; ++k) sum += matched_void_ratio(lab.specimen(k), plan);
  return sum / static_cast<Real>(n);
}

/// The plan's store file of the packing of `c` (friction, cell and seeds named in its hash), "" without a store.
std::string stored_packing_path(const Config& c, const MatchPlan& plan) {
  if (plan.store.empty()) return "";
  std::uint64_t h = store_hash(c);
  const Real v[] = {c.periodic.prep_mu_s, c.box.size[0], c.box.size[1], c.box.size[2]};
  h = fnv1a(v, sizeof v, h);
  const long n[] = {c.particles.count, plan.cell_factor, plan.specimens, static_cast<long>(plan.first_seed)};
  h = fnv1a(n, sizeof n, h);
  if (std::isfinite(plan.data_balls)) h = fnv1a(&plan.data_balls, sizeof plan.data_balls, h);
  return plan.store + "/packing_" + hex16(h) + ".e";
}

/// The plan's mean void ratio after preparation with friction u^2, read from the plan's store where it was kept.
Real void_ratio_at(const Config& base, Real u, const MatchPlan& plan) {
  Config c = base;
  c.periodic.prep_mu_s = u * u;
  const std::string path = stored_packing_path(c, plan);
  Real e = 0;
  if (read_stored(path, [&](int fd) { return get_bytes(fd, &e, sizeof e); })) return e;
  e = prepared_void_ratio(c, plan);
  if (!path.empty()) write_stored(path, std::string(reinterpret_cast<const char*>(&e), sizeof e));
  return e;
}
}  // namespace

std::pair<Real, Real> preparation_reach(const Config& base, const MatchPlan& plan) {
  return {void_ratio_at(base, 0, plan), void_ratio_at(base, 1, plan)};
}

Real prep_friction_for(const Config& base, Real target, Real& reached, bool verbose, const MatchPlan& plan) {
  // Each packing of the plan's specimens takes seconds to minutes: the match reports them (the ends, then the
  // bisection's steps; it may stop early at an end).
  std::optional<Progress> progress;
  if (verbose) {
    // Said before the first packing, which takes the longest (a Hertz-Mindlin base's larger cells: 32 s in silence).
    progress.emplace("triaxdem: matching the void ratio", 2L + plan.steps);
    progress->update(0, "packings");
  }
  long packings = 0;
  auto packed = [&](long count) {
    packings += count;
    if (progress) progress->update(packings, "packings");
  };
  auto at = [&](Real u) {
    const Real e = void_ratio_at(base, u, plan);
    packed(1);
    return e;
  };
  const Real resolution = std::ldexp(Real(1), -plan.steps);
  auto bisect = [&](Real lo, Real hi, Real e_lo, Real e_hi) {
    while (hi - lo > resolution) {
      const Real mid = 0.5 * (lo + hi), e = at(mid);
      (e < target ? lo : hi) = mid;
      (e < target ? e_lo : e_hi) = e;
    }
    const bool low = target - e_lo < e_hi - target;
    reached = low ? e_lo : e_hi;
    return low ? lo * lo : hi * hi;
  };
  if (plan.around >= 0) {
    const auto [lo, hi] = match_bracket(plan.around);
    const Real e_lo = at(lo), e_hi = at(hi);
    if (e_lo <= target && target <= e_hi) return bisect(lo, hi, e_lo, e_hi);
  }
  auto [e_lo, e_hi] = preparation_reach(base, plan);
  packed(2);
  if (verbose)
    std::printf("triaxdem: preparation friction 0 to 1 packs void ratios %.4f to %.4f (mean of %d specimens); "
                "target %.4f\n", e_lo, e_hi, plan.specimens, target);
  // A state far outside what the cell packs is another material state, not a calibration target (a data void
  // ratio of 4.5 was matched by the loosest packing, 0.87, and calibrated on).
  if (target < e_lo - kMaxStateGap || target > e_hi + kMaxStateGap) {
    char msg[360];
    std::snprintf(msg, sizeof msg, "the data's void ratio %.4f is beyond this cell's reach: preparation friction 0 to "
                  "1 packs it at %.4f to %.4f, and a state more than %.2f outside that range cannot be matched (check "
                  "the data's void_ratio or porosity column)", target, e_lo, e_hi, kMaxStateGap);
    throw DataError(msg);
  }
  if (target <= e_lo) return reached = e_lo, 0;
  if (target >= e_hi) return reached = e_hi, 1;
  return bisect(0, 1, e_lo, e_hi);
}

namespace {
/// The data's specimens' balls (their mean) where the plan's cell is walled, smaller and matched on its interior;
/// NaN where it is matched whole.
Real interior_match_balls(const Config& base, const std::vector<TriaxialTest>& tests, const MatchPlan& plan) {
  const Real none = std::numeric_limits<Real>::quiet_NaN();
  if (base.periodic.boundary != CellBoundary::walls || base.calibrate.walled_match != "interior") return none;
  Real sum = 0;
  int n = 0;
  for (const TriaxialTest& t : tests)
    if (std::isfinite(t.void_ratio) && std::isfinite(t.specimen_balls)) sum += t.specimen_balls, ++n;
  const Real cell = static_cast<Real>(base.particles.count * std::max(plan.cell_factor, 1));
  return n > 0 && larger_specimen(sum / n, cell) ? sum / n : none;
}
}  // namespace

Config matched_state(const Config& base, const std::vector<TriaxialTest>& tests, StateMatch& m, bool verbose,
                     const MatchPlan& plan) {
  m = StateMatch{};
  Real sum = 0;
  for (const TriaxialTest& t : tests)
    if (std::isfinite(t.void_ratio)) sum += t.void_ratio, ++m.tests;
  if (m.tests == 0) return base;
  m.target = sum / m.tests;
  m.specimens = plan.specimens;
  MatchPlan own = plan;
  own.data_balls = m.data_balls = interior_match_balls(base, tests, plan);
  Config c = base;
  c.periodic.prep_mu_s = m.prep_mu_s = prep_friction_for(base, m.target, m.reached, verbose, own);
  if (verbose)
    std::printf("triaxdem: the data's void ratio %.4f (mean of %d tests): preparation friction %.4g packs %.4f "
                "(mean of %d specimens%s)\n",
                m.target, m.tests, m.prep_mu_s, m.reached, m.specimens,
                std::isfinite(m.data_balls)
                    ? (", on their interior, as specimens of " + std::to_string(std::lround(m.data_balls)) + " balls")
                          .c_str()
                    : "");
  return c;
}

}  // namespace dem
