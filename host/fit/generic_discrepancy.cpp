#include "host/fit/generic_discrepancy.hpp"

#include <cmath>
#include <limits>

namespace dem {

namespace {
/// The stress an offset's c is counted in: the data's lowest pressures (Table 6, the cross-code files: 50-100 kPa).
constexpr Real kOffsetStress = 100e3;
}  // namespace

const std::vector<GenericShape>& generic_shapes() {
  // Ranges: up to half of q (or of sigma3) either way, the volumetric strain from none to twice, and a hardening
  // slope of sigma3 per 10% strain: larger than any difference between codes or set-ups seen (5-46%).
  static const std::vector<GenericShape> list = {
      {"q scaled", "q (1 + c)", -0.5, 0.5,
       [](TriaxialTest& t, Real c) {
         for (Real& q : t.q) q *= 1 + c;
       }},
      {"q shifted", "q + c sigma3 (beyond the first row)", -0.5, 0.5,
       [](TriaxialTest& t, Real c) {
         for (std::size_t i = 0; i < t.q.size(); ++i)
           if (t.eps_a[i] > 0) t.q[i] += c * t.sigma3;
       }},
      // An apparent cohesion: about the same q at every pressure, so most, relative to q, at the lowest.
      {"q offset", "q + c 100 kPa (beyond the first row)", -0.5, 0.5,
       [](TriaxialTest& t, Real c) {
         for (std::size_t i = 0; i < t.q.size(); ++i)
           if (t.eps_a[i] > 0) t.q[i] += c * kOffsetStress;
       }},
      {"eps_v scaled", "eps_v (1 + c)", -1, 1,
       [](TriaxialTest& t, Real c) {
         for (Real& v : t.eps_v) v *= 1 + c;
       }},
      {"hardening", "q + c sigma3 eps_a", -10, 10,
       [](TriaxialTest& t, Real c) {
         for (std::size_t i = 0; i < t.q.size(); ++i) t.q[i] += c * t.sigma3 * t.eps_a[i];
       }},
  };
  return list;
}

namespace {

/// One whole point of the base search, its tests changeable by a shape: residuals per test at c.
class ShapedPoint {
 public:
  ShapedPoint(const Evaluation& e, const Misfit& misfit, const GenericShape& shape)
      : e_(e), misfit_(misfit), shape_(shape) {
    std::size_t at = 0;
    for (std::size_t k = 0; k < misfit.tests(); ++k) {
      const std::size_t n = static_cast<std::size_t>(misfit.data(k));
      run_.emplace_back(e.r.begin() + static_cast<long>(at), e.r.begin() + static_cast<long>(at + n));
      plain_.push_back(misfit.test_residuals(k, {e.sim[k]}));
      at += n;
    }
    // Residuals beyond the triaxial tests' (a joint fit's other tests, JointTerm) are no shape's: they count as run.
    tail_ = sum_sq(e.r, std::min(at, e.r.size()), e.r.size());
  }
  /// Test k's residuals at c: the run's, plus the change the shape makes to its curve.
  std::vector<Real> residuals(std::size_t k, Real c) const {
    TriaxialTest t = e_.sim[k];
    shape_.apply(t, c);
    summarise(t);
    const std::vector<Real> shaped = misfit_.test_residuals(k, {t});
    std::vector<Real> r = run_[k];
    for (std::size_t i = 0; i < r.size(); ++i) r[i] += shaped[i] - plain_[k][i];
    return r;
  }
  /// chi2 over the data but the held-out part `skip` (none: all), at c.
  Real chi2(Real c, const HeldOutPart* skip) const {
    Real s = tail_;
    for (std::size_t k = 0; k < run_.size(); ++k) {
      const bool held = skip && skip->test == k;
      if (held && skip->local.size() == run_[k].size()) continue;  // a whole test held out
      const std::vector<Real> r = residuals(k, c);
      s += held ? sum_sq(r) - sum_sq(r, skip->local) : sum_sq(r);
    }
    return s;
  }
  /// chi2 of the held-out part alone, at c.
  Real held_chi2(Real c, const HeldOutPart& part) const { return sum_sq(residuals(part.test, c), part.local); }
  /// The c that minimises chi2(c, skip) within the shape's range.
  Real best_c(const HeldOutPart* skip) const {
    const Real lo = shape_.lo, hi = shape_.hi;
    const std::vector<Real> u =
        minimise_unit_box([&](const std::vector<Real>& x) { return chi2(lo + x[0] * (hi - lo), skip); }, 1);
    return lo + u[0] * (hi - lo);
  }
  const Evaluation& evaluation() const { return e_; }

 private:
  const Evaluation& e_;
  const Misfit& misfit_;
  const GenericShape& shape_;
  std::vector<std::vector<Real>> run_, plain_;
  Real tail_ = 0;
};

}  // namespace

std::vector<GenericFit> fit_generic(const CalibrationResult& base, const Misfit& misfit) {
  const int d = static_cast<int>(base.free.size()), n = base.data;
  const HeldOutParts held_out = heldout_parts(misfit);
  std::vector<GenericFit> out;
  for (const GenericShape& shape : generic_shapes()) {
    std::vector<ShapedPoint> points;
    for (const Evaluation& e : base.design)
      if (!e.screened && e.sim.size() == misfit.tests()) points.emplace_back(e, misfit, shape);
    GenericFit f;
    f.shape = shape;
    f.chi2 = std::numeric_limits<Real>::infinity();
    for (const ShapedPoint& p : points) {
      const Real c = p.best_c(nullptr), chi2 = p.chi2(c, nullptr);
      if (chi2 < f.chi2) {
        f.chi2 = chi2;
        f.c = c;
        f.values.clear();
        for (int k = 0; k < d; ++k) f.values.push_back(base.free[k].value(p.evaluation().u[k]));
      }
    }
    f.bic = f.chi2 + (d + 1) * std::log(static_cast<Real>(n));
    // Each held-out part predicted by the shape and point fitted to the rest (heldout_parts, as the extensions'
    // check holds them out).
    f.heldout = held_out.parts.empty() ? std::numeric_limits<Real>::quiet_NaN() : 0;
    for (const HeldOutPart& part : held_out.parts) {
      Real best = std::numeric_limits<Real>::infinity(), held = 0;
      for (const ShapedPoint& p : points) {
        const Real c = p.best_c(&part), others = p.chi2(c, &part);
        if (others < best) best = others, held = p.held_chi2(c, part);
      }
      f.heldout += held;
    }
    out.push_back(f);
  }
  return out;
}

const GenericFit* generic_rival(const std::vector<GenericFit>& generic) {
  const GenericFit* rival = nullptr;
  for (const GenericFit& g : generic)
    if (!rival || g.bic < rival->bic) rival = &g;
  return rival;
}

}  // namespace dem
