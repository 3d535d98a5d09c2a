/// The uncertainty of a calibration's answer (calibrate.hpp, CalibrationResult): the profile intervals, the joint
/// region and the correlation from the residuals' response surfaces at the best run, measured on the scatter
/// specimens where they are given; and the answer moved to another point run (adopt_best, rewhiten).
#include "host/fit/calibrate.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <stdexcept>

namespace dem {

namespace {

/// One specimen a point: the answer's covariance (unit coordinates) from the surfaces' own scatter. Every point's run
/// departs from the surfaces by its specimen's departure and its chaos; the surfaces' value at the answer carries them
/// (the whitening counts that, surrogate_members), and so do their slopes and curvature, which move the minimum with
/// the data's residual as lever. Measured by a wild bootstrap over the specimens: each draw flips the sign of every
/// departure of a specimen at once (its points share its packing), each point's departure its residual from the
/// surfaces over sqrt(1 - its own share); the surfaces are fitted again and minimised, and the minima's covariance is
/// added to the answer's. On a bowl whose noise is known (tests/test_coverage.cpp, 100 data sets) the whitening alone
/// held the truth in 87 joint regions; with the bootstrap's covariance less its first-order part through the value at
/// the answer (what the whitening counts) 90; with all of it 95, as a 95% region should: eight specimens' signs
/// understate the scatter about as much as the value's part counts twice. A fixed seed: the same design gives the same
/// intervals.
Eigen::MatrixXd surface_scatter(const CalibrationResult& r, int d) {
  constexpr int kDraws = 200;
  const int n = static_cast<int>(r.design.size()), m = static_cast<int>(r.surfaces.size());
  const std::vector<std::vector<Real>> proj = surface_projection(r.design, r.best.u);
  const int nb = static_cast<int>(proj.size());
  Eigen::MatrixXd P(nb, n), basis(n, nb);  // coefficients = values x P^T; values at the points = coefficients x basis^T
  for (int j = 0; j < nb; ++j) P.row(j) = Eigen::Map<const Eigen::RowVectorXd>(proj[static_cast<std::size_t>(j)].data(), n);
  Eigen::MatrixXd Y(m, n);
  std::vector<int> specimen(static_cast<std::size_t>(n));
  int specimens = 0;
  for (int i = 0; i < n; ++i) {
    const Evaluation& e = r.design[static_cast<std::size_t>(i)];
    const std::vector<Real> b = QuadraticSurface::basis(e.u);
    basis.row(i) = Eigen::Map<const Eigen::RowVectorXd>(b.data(), nb);
    Y.col(i) = Eigen::Map<const Eigen::VectorXd>(e.r.data(), m);
    specimen[static_cast<std::size_t>(i)] = e.specimen + 1;
    specimens = std::max(specimens, e.specimen + 2);
  }
  const Eigen::MatrixXd fitted = Y * P.transpose() * basis.transpose();  // m x n
  const Eigen::VectorXd own = (basis * P).diagonal();                    // each point's share in its own value
  Eigen::MatrixXd departure = Y - fitted;
  for (int i = 0; i < n; ++i) departure.col(i) /= std::sqrt(std::max(Real(0.05), 1 - own(i)));
  // The draws' minima are sought half a range beyond each edge: clamped to the box, the draws that would cross an
  // edge the answer lies near pile up on it, and their spread understates the answer's scatter along that edge.
  const auto widened = [](std::vector<Real> x) {
    for (Real& v : x) v = 2 * v - Real(0.5);
    return x;
  };
  std::mt19937_64 rng(20261202);
  Eigen::MatrixXd moves(kDraws, d);
  for (int b = 0; b < kDraws; ++b) {
    std::vector<Real> sign(static_cast<std::size_t>(specimens));
    for (Real& v : sign) v = (rng() & 1) ? 1 : -1;
    Eigen::MatrixXd drawn = fitted;
    for (int i = 0; i < n; ++i) drawn.col(i) += sign[static_cast<std::size_t>(specimen[static_cast<std::size_t>(i)])] * departure.col(i);
    const Eigen::MatrixXd C = drawn * P.transpose();  // m x nb: each residual's surface
    const Eigen::MatrixXd Q = C.transpose() * C;      // the chi2 as a quadratic form of the basis
    const std::vector<Real> x = minimise_unit_box([&](const std::vector<Real>& x) {
      const std::vector<Real> bx = QuadraticSurface::basis(widened(x));
      const Eigen::Map<const Eigen::VectorXd> v(bx.data(), nb);
      return v.dot(Q * v);
    }, d);
    const std::vector<Real> u = widened(x);
    for (int k = 0; k < d; ++k) moves(b, k) = u[static_cast<std::size_t>(k)];
  }
  auto covariance = [](Eigen::MatrixXd x) {
    x.rowwise() -= x.colwise().mean();
    return Eigen::MatrixXd(x.transpose() * x / (x.rows() - 1));
  };
  return covariance(moves);
}

/// The rise factors of r's spreads (CalibrationResult, measured on the specimens) at the Jacobian J of the whitened
/// residuals in unit coordinates, and of the surfaces' own scatter where the answer is theirs (surface_scatter); 1
/// where there are neither or J^T J is singular (a flat direction: the intervals already span the range).
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
  // In the model's units: its covariance is scale x (J^T J)^-1.
  const Eigen::MatrixXd surfaces =
      r.surrogate_answer ? Eigen::MatrixXd(surface_scatter(r, d) / r.scale) : Eigen::MatrixXd::Zero(d, d);
  bool first = true;
  auto take = [&](const Eigen::MatrixXd& V) {
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
  };
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
    take(V + surfaces);
  }
  if (first && r.surrogate_answer) take(model + surfaces);
}

/// d residuals / du at u: central differences of the surfaces.
Eigen::MatrixXd surface_jacobian(const std::vector<QuadraticSurface>& surfaces, const std::vector<Real>& u) {
  const int d = static_cast<int>(u.size());
  Eigen::MatrixXd J(static_cast<int>(surfaces.size()), d);
  for (int j = 0; j < d; ++j) {
    std::vector<Real> up = u, dn = u;
    up[j] += 1e-3, dn[j] -= 1e-3;
    for (std::size_t i = 0; i < surfaces.size(); ++i)
      J(static_cast<int>(i), j) = (surfaces[i](up) - surfaces[i](dn)) / 2e-3;
  }
  return J;
}

}  // namespace

std::vector<Real> region_half_widths(const std::vector<QuadraticSurface>& surfaces, const std::vector<Real>& u,
                                     Real rise) {
  const Eigen::MatrixXd J = surface_jacobian(surfaces, u);
  const Eigen::MatrixXd cov = (J.transpose() * J).completeOrthogonalDecomposition().pseudoInverse();
  std::vector<Real> w;
  for (int j = 0; j < cov.rows(); ++j) w.push_back(cov(j, j) > 0 ? std::min(Real(1), std::sqrt(rise * cov(j, j))) : 1);
  return w;
}

Real CalibrationResult::surrogate_members() const {
  if (design.empty() || free.empty()) return 0;
  const std::vector<Real> a = surface_shares(design, best.u, best.u);
  std::vector<Real> by_specimen;
  Real points = 0;
  for (std::size_t i = 0; i < design.size(); ++i) {
    if (design[i].specimen < 0) return 0;
    const std::size_t s = static_cast<std::size_t>(design[i].specimen);
    if (s >= by_specimen.size()) by_specimen.resize(s + 1, 0);
    by_specimen[s] += a[i];
    points += a[i] * a[i];
  }
  Real shared = 0;
  for (Real A : by_specimen) shared += A * A;
  return 1 / std::max(shared, points);
}

void add_uncertainty(CalibrationResult& r) {
  const int d = static_cast<int>(r.free.size());
  if (d == 0 || r.design.size() < 2) return;
  r.surfaces = response_surfaces(r.design, r.best.u);
  r.offset.clear();
  if (r.surrogate_answer) {
    r.best.r.clear();
    for (const QuadraticSurface& q : r.surfaces) r.best.r.push_back(q(r.best.u));
    r.best.chi2 = sum_sq(r.best.r);
    r.offset.assign(r.surfaces.size(), 0);
  } else {
    for (std::size_t i = 0; i < r.surfaces.size(); ++i) r.offset.push_back(r.best.r[i] - r.surfaces[i](r.best.u));
  }
  r.scale = std::max(Real(1), r.best.chi2 / std::max(1, r.data - d));
  const Eigen::MatrixXd J = surface_jacobian(r.surfaces, r.best.u);
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
  const Evaluation* best = r.surrogate_answer ? &r.best : nullptr;  // the answer stays where the surfaces put it
  for (Evaluation& e : r.design) {
    Ensemble one;
    for (const TriaxialTest& t : e.sim) one.push_back({t});
    std::vector<Real> r_new = misfit.residuals(one);
    if (e.r.size() > r_new.size()) r_new.insert(r_new.end(), e.r.begin() + r_new.size(), e.r.end());
    e.r = std::move(r_new);
    e.chi2 = sum_sq(e.r);
    if (!r.surrogate_answer && !e.screened && (!best || e.chi2 < best->chi2)) best = &e;
  }
  if (best) report_at(r, Evaluation(*best), base);
}

}  // namespace dem
