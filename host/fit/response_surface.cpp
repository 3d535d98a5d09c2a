/// The calibration's surrogates (host/fit/calibrate.hpp): quadratic response surfaces of the residuals, weighted
/// towards a centre, and the minimiser over the unit box that searches them.
#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>

#include "host/fit/calibrate.hpp"

namespace dem {

std::vector<Real> QuadraticSurface::basis(const std::vector<Real>& u) {
  std::vector<Real> b{1};
  for (Real x : u) b.push_back(x);
  for (std::size_t i = 0; i < u.size(); ++i)
    for (std::size_t j = i; j < u.size(); ++j) b.push_back(u[i] * u[j]);
  return b;
}

QuadraticSurface::QuadraticSurface(const std::vector<std::vector<Real>>& u, const std::vector<Real>& y,
                                   const std::vector<Real>& w) {
  const int n = static_cast<int>(u.size());
  const int m = static_cast<int>(basis(u.front()).size());
  Eigen::MatrixXd A(n, m);
  Eigen::VectorXd b(n);
  for (int i = 0; i < n; ++i) {
    const std::vector<Real> row = basis(u[i]);
    const Real sw = std::sqrt(w[i]);
    for (int j = 0; j < m; ++j) A(i, j) = sw * row[j];
    b(i) = sw * y[i];
  }
  // Complete orthogonal decomposition: a minimum-norm answer when the design cannot fix every term.
  const Eigen::VectorXd c = A.completeOrthogonalDecomposition().solve(b);
  c_.assign(c.data(), c.data() + m);
}

Real QuadraticSurface::operator()(const std::vector<Real>& u) const {
  const std::vector<Real> b = basis(u);
  Real v = 0;
  for (std::size_t j = 0; j < b.size(); ++j) v += c_[j] * b[j];
  return v;
}

void for_each_grid_point(int d, int n, const std::function<void(const std::vector<Real>&)>& f) {
  std::vector<int> idx(d, 0);
  std::vector<Real> u(d);
  for (;;) {
    for (int k = 0; k < d; ++k) u[k] = static_cast<Real>(idx[k]) / (n - 1);
    f(u);
    int k = 0;
    while (k < d && ++idx[k] == n) idx[k++] = 0;
    if (k == d) return;
  }
}

std::vector<Real> minimise_unit_box(const std::function<Real(const std::vector<Real>&)>& f, int d, int per_axis) {
  if (d == 0) return {};
  const int n = d <= 3 ? per_axis : 7;
  std::vector<Real> best(d, 0.5), u(d);
  Real fbest = std::numeric_limits<Real>::infinity();
  for_each_grid_point(d, n, [&](const std::vector<Real>& x) {
    const Real v = f(x);
    if (v < fbest) fbest = v, best = x;
  });
  for (Real step = 0.5 / (n - 1); step > 1e-4; step /= 2) {
    for (bool moved = true; moved;) {
      moved = false;
      for (int k = 0; k < d; ++k)
        for (Real s : {-step, step}) {
          u = best;
          u[k] = std::clamp(u[k] + s, Real(0), Real(1));
          const Real v = f(u);
          if (v < fbest) fbest = v, best = u, moved = true;
        }
    }
  }
  return best;
}

namespace {

/// The surfaces' weights: a Gaussian of width 0.3 in unit coordinates around `centre`, floor 0.1 (far points still hold
/// the curvature).
std::vector<Real> surface_weights(const std::vector<Evaluation>& pts, const std::vector<Real>& centre) {
  std::vector<Real> w;
  for (const Evaluation& e : pts) {
    Real d2 = 0;
    for (std::size_t k = 0; k < centre.size(); ++k) d2 += (e.u[k] - centre[k]) * (e.u[k] - centre[k]);
    w.push_back(0.1 + std::exp(-d2 / (2 * 0.3 * 0.3)));
  }
  return w;
}

}  // namespace

std::vector<QuadraticSurface> response_surfaces(const std::vector<Evaluation>& pts, const std::vector<Real>& centre) {
  std::vector<std::vector<Real>> u;
  for (const Evaluation& e : pts) u.push_back(e.u);
  const std::vector<Real> w = surface_weights(pts, centre);
  std::vector<QuadraticSurface> s;
  for (std::size_t i = 0; i < pts.front().r.size(); ++i) {
    std::vector<Real> y;
    for (const Evaluation& e : pts) y.push_back(e.r[i]);
    s.emplace_back(u, y, w);
  }
  return s;
}

std::vector<std::vector<Real>> surface_projection(const std::vector<Evaluation>& pts, const std::vector<Real>& centre) {
  const std::vector<Real> w = surface_weights(pts, centre);
  const int n = static_cast<int>(pts.size()), m = static_cast<int>(QuadraticSurface::basis(pts.front().u).size());
  Eigen::MatrixXd B(n, m);
  for (int i = 0; i < n; ++i) {
    const std::vector<Real> row = QuadraticSurface::basis(pts[static_cast<std::size_t>(i)].u);
    for (int j = 0; j < m; ++j) B(i, j) = row[static_cast<std::size_t>(j)];
  }
  const Eigen::VectorXd W = Eigen::Map<const Eigen::VectorXd>(w.data(), n);
  const Eigen::MatrixXd P =
      (B.transpose() * W.asDiagonal() * B).completeOrthogonalDecomposition().pseudoInverse() * B.transpose() *
      W.asDiagonal();
  std::vector<std::vector<Real>> out(static_cast<std::size_t>(m));
  for (int j = 0; j < m; ++j) {
    const Eigen::RowVectorXd row = P.row(j);  // P is column-major: a row is not contiguous
    out[static_cast<std::size_t>(j)].assign(row.data(), row.data() + n);
  }
  return out;
}

std::vector<Real> surface_shares(const std::vector<Evaluation>& pts, const std::vector<Real>& centre,
                                 const std::vector<Real>& u) {
  const std::vector<std::vector<Real>> P = surface_projection(pts, centre);
  const std::vector<Real> b = QuadraticSurface::basis(u);
  std::vector<Real> a(pts.size(), 0);
  for (std::size_t j = 0; j < b.size(); ++j)
    for (std::size_t i = 0; i < a.size(); ++i) a[i] += b[j] * P[j][i];
  return a;
}

}  // namespace dem
