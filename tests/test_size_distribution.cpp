// The balls' size distribution ([particles] psd; host/config/size_distribution.hpp): a sieve table and a lognormal
// drawn as specimens, against their tables; the uniform law as it always drew; bad tables refused by key.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "host/config/size_distribution.hpp"
#include "host/engine/packing.hpp"
#include "test_util.hpp"

using namespace dem;

namespace {

Config cell_of(const std::string& particles, long count, Real solid_fraction) {
  std::string text = "[particles]\ncount = " + std::to_string(count) + "\n" + particles +
                     "\n[box]\nperiodic = [true, true, true]\nsize_mm = [10.0, 10.0, 10.0]\n[solver]\ngravity = [0.0, 0.0, 0.0]\n";
  Config probe = parse_config(text, "psd.toml");
  // The box for the solid fraction asked, from the distribution's mean ball volume.
  const Real side = std::cbrt(count * M_PI / 6 * SizeDistribution(probe.particles).mean_cube() / solid_fraction);
  const std::string mm = std::to_string(1e3 * side);
  const std::size_t at = text.find("[10.0, 10.0, 10.0]");
  text.replace(at, 18, "[" + mm + ", " + mm + ", " + mm + "]");
  return parse_config(text, "psd.toml");
}

/// The Kolmogorov-Smirnov distance of the diameters from the distribution's number CDF.
Real ks_distance(std::vector<Real> d, const SizeDistribution& sizes) {
  std::sort(d.begin(), d.end());
  Real worst = 0;
  const Real n = static_cast<Real>(d.size());
  for (std::size_t i = 0; i < d.size(); ++i) {
    const Real f = sizes.number_passing(d[i]);
    worst = std::max({worst, std::fabs((i + 1) / n - f), std::fabs(i / n - f)});
  }
  return worst;
}

/// The fraction of the balls' mass finer than `size`.
Real mass_passing(const std::vector<Real>& d, Real size) {
  Real fine = 0, all = 0;
  for (Real x : d) {
    all += x * x * x;
    if (x < size) fine += x * x * x;
  }
  return fine / all;
}

std::vector<Real> diameters(const Config& cfg) {
  std::vector<Real> d;
  for (const BallSpec& b : make_packing(cfg)) d.push_back(2 * b.radius);
  return d;
}

}  // namespace

// The quantile draws the table: diameters at n evenly spread quantiles lie within 1/n of the number CDF, and their
// mass passing each sieve is the table's to the midpoint rule's error.
TEST(SizeDistribution, TheQuantileDrawsTheTable) {
  ParticleConfig pc;
  pc.psd = SizeLaw::sieve;
  pc.sieve = {1.0e-3, 1.4e-3, 2.0e-3, 2.8e-3};
  pc.passing = {0, 0.2, 0.7, 1};
  const SizeDistribution sizes(pc);
  std::vector<Real> d;
  for (int k = 0; k < 20000; ++k) d.push_back(sizes.diameter((k + 0.5) / 20000));
  EXPECT_LT(ks_distance(d, sizes), 1.0 / 20000 + 1e-9);
  EXPECT_NEAR(mass_passing(d, 1.4e-3), 0.2, 1e-3);
  EXPECT_NEAR(mass_passing(d, 2.0e-3), 0.7, 1e-3);
}

// A lab's sieve curve drives a specimen: the diameters drawn by number from the percentages passing by mass. The
// Kolmogorov-Smirnov distance of 2,000 balls from the table's number CDF stays below 1.63 / sqrt(n) (its 99% bound,
// 0.036); the mass passing each sieve within 0.04 of the table (3.5 standard errors of a mass fraction over 2,000
// balls of these sizes). Drawn as a cell's random insertion draws them, at the solid fraction of the shipped cells.
TEST(SizeDistribution, ASieveTablesSpecimenMatchesItsTable) {
  const Config cfg = cell_of("psd = \"sieve\"\nsieve_mm = [1.0, 1.4, 2.0, 2.8]\npassing_pct = [0, 20, 70, 100]\n",
                             2000, 0.15);
  const SizeDistribution sizes(cfg.particles);
  const std::vector<Real> d = diameters(cfg);
  ASSERT_EQ(d.size(), 2000u);
  EXPECT_LT(ks_distance(d, sizes), 1.63 / std::sqrt(2000.0));
  EXPECT_NEAR(mass_passing(d, 1.4e-3), 0.20, 0.04);
  EXPECT_NEAR(mass_passing(d, 2.0e-3), 0.70, 0.04);
  EXPECT_GE(*std::min_element(d.begin(), d.end()), 1.0e-3 * (1 - 1e-12));
  EXPECT_LE(*std::max_element(d.begin(), d.end()), 2.8e-3 * (1 + 1e-12));
  EXPECT_NEAR(cfg.particles.diameter, sizes.mean(), 1e-15) << "the mean diameter is the distribution's";
}

// A lognormal by mass: half the mass finer than its median D50, and about 84% finer than D50 e^s (Phi(1), renormalised
// to the cut at 3 s: 0.8413); the same bounds. The number median lies at D50 e^(-3 s^2).
TEST(SizeDistribution, ALognormalByMassHasItsMedianByMass) {
  const Config cfg = cell_of("psd = \"lognormal\"\nmedian_mm = 2.0\nlog_sd = 0.2\n", 2000, 0.15);
  const SizeDistribution sizes(cfg.particles);
  const std::vector<Real> d = diameters(cfg);
  EXPECT_LT(ks_distance(d, sizes), 1.63 / std::sqrt(2000.0));
  EXPECT_NEAR(mass_passing(d, 2.0e-3), 0.5, 0.04);
  EXPECT_NEAR(mass_passing(d, 2.0e-3 * std::exp(0.2)), 0.8413, 0.04);
  EXPECT_NEAR(sizes.passing(2.0e-3), 0.5, 1e-12);
  EXPECT_NEAR(sizes.number_passing(2.0e-3 * std::exp(-3 * 0.2 * 0.2)), 0.5, 0.01);
}

// The uniform law draws as it always drew: d_min + (d_max - d_min) u about the mean diameter, the mean of d^3 that
// of the uniform spread, so the shipped configs' specimens keep their bits (Reference.* holds them).
TEST(SizeDistribution, TheUniformLawIsTheSpreadAboutTheMeanDiameter) {
  ParticleConfig pc;
  pc.diameter = 2e-3;
  pc.diameter_ratio = 1.5;
  const SizeDistribution sizes(pc);
  EXPECT_DOUBLE_EQ(sizes.smallest(), 1.6e-3);
  EXPECT_DOUBLE_EQ(sizes.largest(), 2.4e-3);
  EXPECT_DOUBLE_EQ(sizes.diameter(0.5), 2e-3);
  EXPECT_NEAR(sizes.mean_cube(), (std::pow(2.4e-3, 4) - std::pow(1.6e-3, 4)) / (4 * 0.8e-3), 1e-20);
}

TEST(SizeDistribution, ABadTableIsRefusedByItsKey) {
  auto error = [](const std::string& particles) {
    try {
      parse_config("[particles]\ncount = 10\n" + particles, "bad.toml");
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(error("psd = \"sieve\"\nsieve_mm = [1.0, 2.0]\npassing_pct = [0, 90]\n").find("passing_pct"),
            std::string::npos);
  EXPECT_NE(error("psd = \"sieve\"\nsieve_mm = [2.0, 1.0]\npassing_pct = [0, 100]\n").find("sieve_mm: the sizes must "
                                                                                         "increase"),
            std::string::npos);
  EXPECT_NE(error("psd = \"sieve\"\nsieve_mm = [1.0, 2.0, 3.0]\npassing_pct = [0, 100]\n").find("one value a sieve"),
            std::string::npos);
  EXPECT_NE(error("psd = \"lognormal\"\nmedian_mm = 2.0\n").find("log_sd: missing"), std::string::npos);
  EXPECT_NE(error("psd = \"lognormal\"\nmedian_mm = 2.0\nlog_sd = 0.2\ndiameter_mm = 2.0\n").find("diameter_mm: not "
                                                                                                 "with psd"),
            std::string::npos);
  EXPECT_NE(error("median_mm = 2.0\n").find("belongs to psd = \"lognormal\""), std::string::npos);
  EXPECT_NE(error("psd = \"gaussian\"\n").find("allowed: lognormal, sieve, uniform"), std::string::npos);
  EXPECT_NE(error("psd = \"lognormal\"\nmedian_mm = 2.0\nlog_sd = 0.2\n[box]\nfill = \"lattice\"\n")
                .find("[box] fill"),
            std::string::npos);
}
