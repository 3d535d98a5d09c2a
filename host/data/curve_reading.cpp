#include "host/data/curve_reading.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>

namespace dem {

Real feature_window(Real e) { return std::min(0.3 * e, 0.0025); }

Real curve_value(const std::vector<Real>& eps_a, const std::vector<Real>& v, Real e) {
  if (eps_a.empty() || e < eps_a.front() || e > eps_a.back()) return kNaN;
  const Real h = feature_window(e);
  const auto lo = std::lower_bound(eps_a.begin(), eps_a.end(), e - h) - eps_a.begin();
  const auto hi = std::upper_bound(eps_a.begin(), eps_a.end(), e + h) - eps_a.begin();
  if (hi - lo >= 3) {
    Real sx = 0, sy = 0, sxx = 0, sxy = 0;
    const Real n = static_cast<Real>(hi - lo);
    for (auto i = lo; i < hi; ++i) {
      const Real x = eps_a[i] - e;
      sx += x, sy += v[i], sxx += x * x, sxy += x * v[i];
    }
    const Real det = n * sxx - sx * sx;
    if (det > 0) return (sxx * sy - sx * sxy) / det;  // the line's value at x = 0
  }
  return interpolate(eps_a, v, e);
}

Real interpolate(const std::vector<Real>& eps_a, const std::vector<Real>& y, Real e) {
  const auto j = std::lower_bound(eps_a.begin(), eps_a.end(), e) - eps_a.begin();
  if (j == 0 || eps_a[j] == e) return y[j];
  const Real w = (e - eps_a[j - 1]) / (eps_a[j] - eps_a[j - 1]);
  return (1 - w) * y[j - 1] + w * y[j];
}

/// Residuals about a least-squares parabola through the 21 rows around each row: the trend of a smooth curve, its
/// bend included (the stiff start of a triaxial curve, the peak), is removed and its noise kept. The median
/// absolute residual keeps the scale robust to the few rows where the trend still shows. A correlated noise is
/// partly taken up as trend (an AR(1) of 0.7 reads 0.37, tests/test_misfit.cpp).
RowNoise row_noise(const std::vector<Real>& eps_a, const std::vector<Real>& v) {
  constexpr int kHalf = 10, kRows = 2 * kHalf + 1;
  const int n = static_cast<int>(v.size());
  if (n < kMinNoiseRows) return {kNaN, kNaN};
  std::vector<Real> e;
  for (int i = kHalf; i < n - kHalf; ++i) {
    Eigen::Matrix<Real, kRows, 3> A;
    Eigen::Matrix<Real, kRows, 1> y;
    const Real h = eps_a[i + kHalf] - eps_a[i - kHalf];  // scales x to O(1) for the conditioning
    for (int j = 0; j < kRows; ++j) {
      const Real x = (eps_a[i - kHalf + j] - eps_a[i]) / h;
      A(j, 0) = 1, A(j, 1) = x, A(j, 2) = x * x;
      y(j) = v[i - kHalf + j];
    }
    const Eigen::Matrix<Real, 3, 1> c = A.colPivHouseholderQr().solve(y);
    e.push_back(v[i] - c(0));
  }
  std::vector<Real> a(e.size());
  std::transform(e.begin(), e.end(), a.begin(), [](Real x) { return std::fabs(x); });
  std::nth_element(a.begin(), a.begin() + a.size() / 2, a.end());
  // 1.4826 MAD is the standard deviation of Gaussian noise; a parabola fitted to kRows rows takes three of their
  // degrees of freedom, which the factor puts back.
  const Real sd = 1.4826 * a[a.size() / 2] * std::sqrt(Real(kRows) / (kRows - 3));
  Real s0 = 0, s1 = 0;
  for (std::size_t i = 0; i + 1 < e.size(); ++i) s0 += e[i] * e[i], s1 += e[i] * e[i + 1];
  // Residuals about a fitted curve lean negative at lag 1 even for white noise; a negative estimate is read as 0.
  const Real rho = s0 > 0 ? std::clamp(s1 / s0, Real(0), Real(0.95)) : 0;
  return {sd, rho};
}

TriaxialTest mean_curve(const std::vector<TriaxialTest>& members) {
  const TriaxialTest* first = nullptr;
  for (const TriaxialTest& t : members)
    if (!t.q.empty() && std::isfinite(t.q_peak)) {
      first = &t;
      break;
    }
  if (!first) return members.front();
  TriaxialTest out = *first;
  const bool volume = !first->eps_v.empty();
  for (std::size_t i = 0; i < out.eps_a.size(); ++i) {
    Real q = 0, ev = 0, vr = 0;
    int n = 0;
    for (const TriaxialTest& t : members) {
      if (t.q.empty() || !std::isfinite(t.q_peak) || out.eps_a[i] > t.eps_a.back()) continue;
      q += interpolate(t.eps_a, t.q, out.eps_a[i]);
      if (volume) ev += interpolate(t.eps_a, t.eps_v, out.eps_a[i]);
      vr += t.void_ratio;
      ++n;
    }
    out.q[i] = q / n;
    if (volume) out.eps_v[i] = ev / n;
    out.void_ratio = vr / n;
  }
  summarise(out);
  return out;
}

}  // namespace dem
