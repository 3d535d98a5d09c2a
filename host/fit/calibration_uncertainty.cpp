/// The uncertainty of a calibration's answer (calibrate.hpp, CalibrationResult): the profile intervals, the joint
/// region and the correlation from the residuals' response surfaces at the best run, measured on the scatter
/// specimens where they are given; and the answer moved to another point run (adopt_best, rewhiten).
#include "host/fit/calibrate.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace dem {

namespace {

/// The rise factors of r's spreads (CalibrationResult, measured on the specimens) at the Jacobian J of the whitened
/// residuals in unit coordinates; 1 where there are none or J^T J is singular (a flat direction: the intervals
/// already span the range).
void specimen_factors(CalibrationResult& r, const Eigen::MatrixXd& J) {
  const int d = static_cast<int>(J.cols()), n = static_cast<int>(J.rows());
  r.rise_factor.assign(d, 1);
  r.region_factor = 1;
  const Eigen::MatrixXd A = J.transpose() * J;
  const Eigen::LLT<Eigen::MatrixXd> llt(A);
  if (llt.info() != Eigen::Success) return;
  const Eigen::MatrixXd model = llt.solve(Eigen::MatrixXd::Identity(d, d));  // (J^T J)^-1
  const Eigen::MatrixXd G = model * J.transpose();
  const Eigen::MatrixXd L = llt.matrixL();
  bool first = true;
  for (const SpecimenSpread& s : r.spreads) {
    const int S = static_cast<int>(s.specimen.size());
    if (S < kMinSpreadSpecimens || s.modelled.size() != static_cast<std::size_t>(n) * n || s.tests.empty() ||
        s.tests.back() != n)
      continue;
    const Eigen::Map<const Eigen::MatrixXd> M(s.modelled.data(), n, n);
    Eigen::MatrixXd V = model - G * M * G.transpose();
    const Real nu = S - 1, weight = nu / (nu - 2) / (S - 1);
    for (int k = 0; k < S; ++k) {
      const Eigen::Map<const Eigen::VectorXd> sp(s.specimen[k].data(), n), en(s.ensemble[k].data(), n);
      for (std::size_t t = 0; t + 1 < s.tests.size(); ++t) {  // the data's specimens: one a test
        const int from = s.tests[t], len = s.tests[t + 1] - from;
        const Eigen::VectorXd g = G.middleCols(from, len) * sp.segment(from, len);
        V += weight * g * g.transpose();
      }
      const Eigen::VectorXd g = G * en;  // the ensemble's members: the same packings in every test
      V += weight * g * g.transpose();
    }
    const Eigen::VectorXd lambda =
        Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(L.transpose() * V * L).eigenvalues().cwiseMax(0);
    const Real s1 = lambda.sum(), s2 = lambda.squaredNorm();
    const Real region = s1 > 0 ? (s2 / s1) * chi2_quantile(s1 * s1 / s2, 1.645) / chi2_quantile(d, 1.645) : 1;
    r.region_factor = first ? region : std::max(r.region_factor, region);
    for (int j = 0; j < d; ++j) {
      const Real f = std::max(Real(0), V(j, j)) / model(j, j);
      r.rise_factor[j] = first ? f : std::max(r.rise_factor[j], f);
    }
    first = false;
  }
}

}  // namespace

void add_uncertainty(CalibrationResult& r) {
  const int d = static_cast<int>(r.free.size());
  if (d == 0 || r.design.size() < 2) return;
  r.surfaces = response_surfaces(r.design, r.best.u);
  r.offset.clear();
  for (std::size_t i = 0; i < r.surfaces.size(); ++i) r.offset.push_back(r.best.r[i] - r.surfaces[i](r.best.u));
  r.scale = std::max(Real(1), r.best.chi2 / std::max(1, r.data - d));
  // J = d residuals / du at the best point (central differences of the surfaces).
  Eigen::MatrixXd J(static_cast<int>(r.surfaces.size()), d);
  for (int j = 0; j < d; ++j) {
    std::vector<Real> up = r.best.u, dn = r.best.u;
    up[j] += 1e-3, dn[j] -= 1e-3;
    for (std::size_t i = 0; i < r.surfaces.size(); ++i)
      J(static_cast<int>(i), j) = (r.surfaces[i](up) - r.surfaces[i](dn)) / 2e-3;
  }
  specimen_factors(r, J);
  // Profile intervals: each parameter on a grid of its unit range, the surrogate minimised over the others.
  const Real best = r.surrogate_chi2(r.best.u);
  r.interval.clear();
  for (int j = 0; j < d; ++j) {
    constexpr int kGrid = 201;
    std::vector<Real> profile(kGrid);
    for (int g = 0; g < kGrid; ++g) {
      const Real t = static_cast<Real>(g) / (kGrid - 1);
      const std::vector<Real> rest = minimise_unit_box([&](const std::vector<Real>& x) {
        std::vector<Real> u(x);
        u.insert(u.begin() + j, t);
        return r.surrogate_chi2(u);
      }, d - 1, 11);
      std::vector<Real> u(rest);
      u.insert(u.begin() + j, t);
      profile[g] = r.surrogate_chi2(u);
    }
    const Real rise = 3.841 * r.scale * r.rise_factor[j];
    int at = static_cast<int>(std::lround(r.best.u[j] * (kGrid - 1)));
    int lo = at, hi = at;
    while (lo > 0 && profile[lo - 1] - best <= rise) --lo;
    while (hi < kGrid - 1 && profile[hi + 1] - best <= rise) ++hi;
    r.interval.emplace_back(r.free[j].value(static_cast<Real>(lo) / (kGrid - 1)),
                            r.free[j].value(static_cast<Real>(hi) / (kGrid - 1)));
  }
  // Correlation: Gauss-Newton's at the best point.
  const Eigen::MatrixXd cov = (J.transpose() * J).completeOrthogonalDecomposition().pseudoInverse();
  r.correlation.assign(d, std::vector<Real>(d, 0));
  for (int a = 0; a < d; ++a)
    for (int b = 0; b < d; ++b) {
      const Real den = std::sqrt(cov(a, a) * cov(b, b));
      r.correlation[a][b] = den > 0 ? cov(a, b) / den : (a == b ? 1 : 0);
    }
}


Real CalibrationResult::surrogate_chi2(const std::vector<Real>& u) const {
  Real c = 0;
  for (std::size_t i = 0; i < surfaces.size(); ++i) {
    const Real v = surfaces[i](u) + offset[i];
    c += v * v;
  }
  return c;
}

Real CalibrationResult::region_rise(const std::vector<Real>& values) const {
  std::vector<Real> u;
  for (std::size_t k = 0; k < free.size(); ++k) {
    if (values[k] < free[k].lo || values[k] > free[k].hi) return std::numeric_limits<Real>::infinity();
    u.push_back(free[k].unit(values[k]));
  }
  return (surrogate_chi2(u) - surrogate_chi2(best.u)) /
         (chi2_95(static_cast<int>(free.size())) * scale * region_factor);
}

Real CalibrationResult::flat_share() const {
  const int d = static_cast<int>(free.size());
  if (d == 0 || surfaces.empty()) return 0;
  const int n = d <= 3 ? 21 : 7;
  const Real limit = surrogate_chi2(best.u) + chi2_95(d) * scale * region_factor;
  long inside = 0, all = 0;
  for_each_grid_point(d, n, [&](const std::vector<Real>& u) {
    inside += surrogate_chi2(u) <= limit;
    ++all;
  });
  return static_cast<Real>(inside) / all;
}

std::vector<std::string> CalibrationResult::inseparable() const {
  std::vector<std::string> out;
  for (std::size_t a = 0; a < correlation.size(); ++a)
    for (std::size_t b = a + 1; b < correlation.size(); ++b)
      if (std::fabs(correlation[a][b]) > 0.9) {
        char c[32];
        std::snprintf(c, sizeof c, " (%+.2f)", correlation[a][b]);
        out.push_back(free[a].name + " and " + free[b].name + c);
      }
  return out;
}

namespace {

/// Makes `best` the reported point: its values, the model (`base` with them) and the uncertainty at it.
void report_at(CalibrationResult& r, const Evaluation& best, const Model& base) {
  r.best = best;
  r.model = base;
  r.values.clear();
  for (std::size_t k = 0; k < r.free.size(); ++k) {
    r.values.push_back(r.free[k].value(best.u[k]));
    set_param(r.model, r.free[k].name, r.values.back());
  }
  add_uncertainty(r);
}

}  // namespace

void adopt_best(CalibrationResult& r, const Evaluation& better, const Model& base) {
  r.design.push_back(better);
  report_at(r, better, base);
}

void measure_on_specimens(CalibrationResult& r, std::vector<SpecimenSpread> spreads) {
  r.spreads = std::move(spreads);
  add_uncertainty(r);
}

void rewhiten(CalibrationResult& r, const Misfit& misfit, const Model& base) {
  r.spreads = misfit.specimen_spreads();
  const Evaluation* best = nullptr;
  for (Evaluation& e : r.design) {
    Ensemble one;
    for (const TriaxialTest& t : e.sim) one.push_back({t});
    e.r = misfit.residuals(one);
    e.chi2 = sum_sq(e.r);
    if (!e.screened && (!best || e.chi2 < best->chi2)) best = &e;
  }
  if (best) report_at(r, Evaluation(*best), base);
}

}  // namespace dem
