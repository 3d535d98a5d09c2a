#include "host/data/measured.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "host/data/curve_reading.hpp"

/// A curve's summary quantities (summarise, measured.hpp), for measured and simulated curves alike.

namespace dem {

namespace {

/// Mean of v over the rows whose axial strain lies within +-h of eps_a[i], h = min(half, distance to either end
/// of the curve): a window in strain, so that uneven row spacing does not change the smoothing, and symmetric,
/// so that a straight line comes out unchanged up to the very ends.
std::vector<Real> smooth(const std::vector<Real>& eps_a, const std::vector<Real>& v, Real half) {
  std::vector<Real> out(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) {
    const Real h = std::min({half, eps_a[i] - eps_a.front(), eps_a.back() - eps_a[i]}) + 1e-12;
    Real sum = v[i];
    int n = 1;
    for (std::size_t j = i; j-- > 0 && eps_a[j] >= eps_a[i] - h;) sum += v[j], ++n;
    for (std::size_t j = i + 1; j < v.size() && eps_a[j] <= eps_a[i] + h; ++j) sum += v[j], ++n;
    out[i] = sum / n;
  }
  return out;
}
}  // namespace

Real friction_angle_deg(Real q, Real sigma3) { return std::asin(q / (q + 2 * sigma3)) * 180 / M_PI; }

void summarise(TriaxialTest& t) {
  if (t.q.empty()) return;
  const std::vector<Real> q = smooth(t.eps_a, t.q, kSmoothHalfWidth);
  // The peak is sought where the window is whole: towards either end it shrinks to the end row alone, whose
  // scatter would pass for a peak (the last record of a plateau often does). A curve shorter than one window
  // is searched whole.
  std::size_t lo = 0, hi = q.size();
  while (lo < hi && t.eps_a[lo] - t.eps_a.front() < kSmoothHalfWidth - 1e-12) ++lo;
  while (hi > lo && t.eps_a.back() - t.eps_a[hi - 1] < kSmoothHalfWidth - 1e-12) --hi;
  if (lo >= hi) lo = 0, hi = q.size();
  const auto k = std::max_element(q.begin() + lo, q.begin() + hi) - q.begin();
  t.q_peak = q[k];
  t.eps_a_peak = t.eps_a[k];
  auto q_at = [&](Real e) { return e < t.eps_a.front() || e > t.eps_a.back() ? kNaN : interpolate(t.eps_a, q, e); };
  t.q_1pct = q_at(kEarlyStrain);
  t.q_3pct = q_at(kMidStrain);
  // q at the end: the mean over the last strain window (one raw row carries the full scatter).
  Real sum = 0;
  int n = 0;
  for (std::size_t i = t.q.size(); i-- > 0 && t.eps_a[i] >= t.eps_a.back() - kEndWindow;) sum += t.q[i], ++n;
  t.q_end = sum / n;
  // Initial stiffness: least-squares slope through the first row of q against eps_a over the first
  // kInitialWindow of strain (raw rows: smoothing would blur the start).
  Real sxy = 0, sxx = 0;
  for (std::size_t i = 1; i < t.q.size() && t.eps_a[i] - t.eps_a[0] <= kInitialWindow + 1e-12; ++i) {
    const Real x = t.eps_a[i] - t.eps_a[0];
    sxy += x * (t.q[i] - t.q[0]);
    sxx += x * x;
  }
  t.e_ini = sxx > 0 ? sxy / sxx : kNaN;
  t.max_dilatancy = kNaN;
  if (t.eps_v.empty()) return;
  // Maximum dilatancy -d eps_v / d eps_a: the slope of the smoothed eps_v over one window of strain.
  const std::vector<Real> ev = smooth(t.eps_a, t.eps_v, kSmoothHalfWidth);
  t.max_dilatancy = 0;
  for (std::size_t i = 0, j = 0; i < ev.size(); ++i) {
    while (j < ev.size() && t.eps_a[j] < t.eps_a[i] + 2 * kSmoothHalfWidth - 1e-12) ++j;
    if (j >= ev.size()) break;
    t.max_dilatancy = std::max(t.max_dilatancy, -(ev[j] - ev[i]) / (t.eps_a[j] - t.eps_a[i]));
  }
}

}  // namespace dem
