/// The simulator's finite-cell bias (host/cell_bias.hpp) without the simulator: its extrapolation to the data's
/// specimen, its estimate beyond the check's own scatter, and what counting it does to a misfit.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "host/cell_bias.hpp"

using namespace dem;

namespace {

/// q rising hyperbolically to 1.5 sigma3, eps_v contracting to 0.2% then dilating; rows every 0.02% to 10%.
MeasuredTest curve(Real sigma3, Real q_factor = 1) {
  MeasuredTest t;
  t.material = "A";
  t.sigma3 = sigma3;
  for (Real e = 0; e <= 0.1 + 1e-12; e += 2e-4) {
    t.eps_a.push_back(e);
    t.q.push_back(q_factor * 1.5 * sigma3 * e / (e + 0.004));
    t.eps_v.push_back(0.002 * e / 0.01 * std::exp(1 - e / 0.01) - 0.3 * std::max(Real(0), e - 0.02));
  }
  summarise(t);
  return t;
}

/// Eight members scattering by +-1% of q about `t`.
std::vector<MeasuredTest> members(const MeasuredTest& t) {
  std::vector<MeasuredTest> out;
  for (int k = 0; k < 8; ++k) {
    MeasuredTest m = t;
    for (Real& q : m.q) q *= k % 2 ? 1.01 : 0.99;
    summarise(m);
    out.push_back(m);
  }
  return out;
}

Real chi2(const std::vector<Real>& r) {
  Real s = 0;
  for (Real x : r) s += x * x;
  return s;
}

}  // namespace

// Under the power law N^-1/2, the difference between cells of N and 4N is half of what separates N from an unlimited
// specimen (N^-1/2 - (4N)^-1/2 = N^-1/2 / 2), all of what separates N from 4N, 3/4 / (1/2) of what separates N from
// 16N, and nothing where the data's specimen is the simulator's size; a specimen smaller than the simulator's is
// as far off the other way (N / 4: |1 - 2| / (1/2) = 2).
TEST(CellBias, ExtrapolatesTheDifferenceByThePowerLaw) {
  const Real inf = std::numeric_limits<Real>::quiet_NaN();
  EXPECT_DOUBLE_EQ(cell_bias_extrapolation(120, 4, 480), 1);
  EXPECT_DOUBLE_EQ(cell_bias_extrapolation(120, 4, inf), 2);
  EXPECT_DOUBLE_EQ(cell_bias_extrapolation(120, 4, 1920), 1.5);
  EXPECT_DOUBLE_EQ(cell_bias_extrapolation(120, 4, 120), 0);
  EXPECT_DOUBLE_EQ(cell_bias_extrapolation(120, 4, 30), 2);
}

// Only the difference beyond the check's own scatter is a bias: a difference as large as its own standard
// deviation counts nothing, one of 5 against a standard deviation of 3 counts 4, and a feature that one side
// lacks counts nothing.
TEST(CellBias, CountsOnlyTheDifferenceBeyondItsOwnScatter) {
  EXPECT_EQ(cell_bias_sd(0.5, 0.25, 2), 0);
  EXPECT_EQ(cell_bias_sd(-0.25, 0.25, 2), 0);
  EXPECT_DOUBLE_EQ(cell_bias_sd(5, 9, 1), 4);
  EXPECT_DOUBLE_EQ(cell_bias_sd(-5, 9, 2), 8);
  EXPECT_EQ(cell_bias_sd(std::numeric_limits<Real>::quiet_NaN(), 0, 2), 0);
}

// A simulator whose q lies 10% above precise data everywhere (a cell's bias) misses them by far more than the
// data's noise; with that bias counted, correlated along strain, the same curve fits: the whole shift along the
// curve is one correlated deviation of about one standard deviation, so chi2 is about 1 (below 4: two of them,
// allowing for the curve's shape, 1.1 q is not exactly the correlated pattern). A difference in eps_v, which the
// bias does not cover, is still seen in full.
TEST(CellBias, ACountedBiasTakesUpTheShiftItMeasuredAndNothingElse) {
  const MeasuredTest data = curve(100e3);
  Misfit m({data}, NoiseOptions(), Ensemble{members(data)}, 8, 0.1);
  const MeasuredTest shifted = curve(100e3, 1.1);
  MeasuredTest contracts = data;
  for (Real& v : contracts.eps_v) v += 2e-3;
  summarise(contracts);
  const Real before = chi2(m.test_residuals(0, {shifted})), volume_before = chi2(m.test_residuals(0, {contracts}));
  ASSERT_GT(before, 50) << "the lab's 2% specimen floor: a 10% shift is far outside the noise";
  std::vector<std::vector<Real>> sd(1);
  const std::vector<Real> big = m.mean_values(0, {shifted}), small = m.mean_values(0, {data});
  for (std::size_t i = 0; i < big.size(); ++i) sd[0].push_back(cell_bias_sd(big[i] - small[i], 0, 1));
  m.add_cell_bias(sd, "test");
  EXPECT_LT(chi2(m.test_residuals(0, {shifted})), 4);
  EXPECT_NEAR(chi2(m.test_residuals(0, {contracts})), volume_before, 1e-6 * volume_before);
  for (const Feature& f : m.features(0))
    if (f.quantity == 0) EXPECT_NEAR(f.cell_sd, 0.1 * f.measured, 1e-6 * f.measured) << f.name;
}
