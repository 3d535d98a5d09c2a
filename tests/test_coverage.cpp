// Coverage of the calibration's 95% intervals and joint region on a simulator whose truth is known and whose noise is
// the misfit's: the search and the uncertainty of host/fit/calibrate.cpp, without the DEM (perf/coverage.sh measures
// the same on the program's own synthetic data; docs/calibration.md, Coverage).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "host/fit/calibrate.hpp"
#include "host/util/fnv1a.hpp"

namespace dem {
namespace {

/// Residuals as the misfit whitens them: r_i = f_i(x, y) + c_i + chaos_i(x, y) - d_i in units of the total standard
/// deviation, (x, y) the unit coordinates of (mu_s, mu_r). f rises with the friction as q does, most data along one
/// combination of the two (they trade against each other, as on Table 6's S-1); d = f(truth) + the data's own noise;
/// c is the ensemble mean's departure shared by every point (common random numbers), chaos a small cell's departure
/// that changes from point to point. The three variances add to one, so the misfit's noise is right by construction.
struct NoisyBowl {
  static constexpr int kData = 30;
  static constexpr Real kData_sd = 0.8, kCommon_sd = 0.4, kChaos_sd = 0.447;  // 0.64 + 0.16 + 0.2 = 1
  std::vector<FreeParam> free;
  std::vector<Real> d, c;
  unsigned seed;
  Real x0, y0;

  NoisyBowl(const Model& base, Real at_x, Real at_y, unsigned s)
      : free{free_param("mu_s", base), free_param("mu_r", base)}, d(kData), c(kData), seed(s), x0(at_x), y0(at_y) {
    std::mt19937_64 rng(s);
    std::normal_distribution<Real> z(0, 1);
    for (int i = 0; i < kData; ++i) {
      d[i] = f(i, x0, y0) + kData_sd * z(rng);
      c[i] = kCommon_sd * z(rng);
    }
  }
  static Real f(int i, Real x, Real y) {
    const Real along = 1 + 0.5 * (i % 3), across = (i % 5) - 2.0;
    return 6 * along * (std::exp(1.2 * (x + 0.7 * y)) - 1) / 1.2 + 1.5 * across * y;
  }
  Simulator simulator() const {
    return [this](const Model& m, Real) {
      const Real x = free[0].unit(m.law.mu_s), y = free[1].unit(m.law.mu_r);
      // The chaos is a function of the point and the seed: the same point run twice gives the same run.
      const std::uint64_t h = fnv1a(&x, sizeof x, fnv1a(&y, sizeof y, kFnv1aOffset + seed));
      std::mt19937_64 rng(h);
      std::normal_distribution<Real> z(0, 1);
      SimulatedPoint s;
      for (int i = 0; i < kData; ++i) s.r.push_back(f(i, x, y) + c[i] + kChaos_sd * z(rng) - d[i]);
      return s;
    };
  }
};

// Over 100 data sets with the truth drawn across the inner box, a 95% interval must hold the truth in about 95 (sd
// 2.2); at least 90 allows 2.3 sd of chance, and a method whose intervals hold it 85% of the time or less fails with
// probability above 0.9 (binomial). The same for the joint 95% region (region_rise at most 1).
TEST(Coverage, IntervalsAndTheJointRegionHoldTheTruthAtTheirLevel) {
  Model base;
  base.law.mu_s = 0.15;
  base.law.mu_r = 0.015;
  constexpr int kCases = 100;
  std::mt19937_64 draw(2026);
  std::uniform_real_distribution<Real> inner(0.15, 0.85);
  int held[2] = {0, 0}, joint = 0;
  Real width[2] = {0, 0};
  for (int k = 0; k < kCases; ++k) {
    const Real x0 = inner(draw), y0 = inner(draw);
    const NoisyBowl bowl(base, x0, y0, 1000 + k);
    const CalibrationResult r = calibrate(bowl.simulator(), base, bowl.free, NoisyBowl::kData);
    const std::vector<Real> truth{bowl.free[0].value(x0), bowl.free[1].value(y0)};
    for (int j = 0; j < 2; ++j) {
      held[j] += r.interval[j].first <= truth[j] && truth[j] <= r.interval[j].second;
      width[j] += (r.free[j].unit(r.interval[j].second) - r.free[j].unit(r.interval[j].first)) / kCases;
    }
    joint += r.region_rise(truth) <= 1;
  }
  std::printf("coverage over %d cases: mu_s %d, mu_r %d, joint %d; mean widths in unit coordinates %.3f, %.3f\n",
              kCases, held[0], held[1], joint, width[0], width[1]);
  EXPECT_GE(held[0], 90);
  EXPECT_GE(held[1], 90);
  EXPECT_GE(joint, 90);
}

}  // namespace
}  // namespace dem
