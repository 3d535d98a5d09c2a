#pragma once
/// The balls' size distribution of a [particles] table: the one place that knows the smallest and largest diameter,
/// the means, and how a diameter is drawn.
///   uniform:   by number between d_min and d_max = d_min * diameter_ratio, with mean diameter_mm;
///   lognormal: ln(d) normal by mass, median D50 and standard deviation s, cut at D50 exp(+-3 s) (0.27% of the mass
///              left out); by number it is lognormal too, with median D50 exp(-3 s^2) (the mass of a ball is d^3);
///   sieve:     the mass finer than each sieve given, spread evenly in d between two sieves, so that by number the
///              density between sieves a and b falls as d^-3.
/// Labs give a distribution by mass (a sieve curve); a specimen is drawn ball by ball, by number: one uniform number
/// a ball, through the quantile of the number distribution.
#include <string>
#include <vector>

#include "host/config/config.hpp"

namespace dem {

class TableReader;

/// Reads [particles] psd and the keys of its distribution from `pt` into `pc`, refusing by key a table that is no
/// distribution or keys of another law; the mean diameter of a lognormal or sieve distribution worked out from it.
void read_size_distribution(TableReader& pt, ParticleConfig& pc);

class SizeDistribution {
 public:
  /// Throws std::invalid_argument on a table that is no distribution (the config's checks name the keys first).
  explicit SizeDistribution(const ParticleConfig& pc);

  Real smallest() const { return dmin_; }  ///< m
  Real largest() const { return dmax_; }   ///< m
  Real mean() const { return mean_; }      ///< m, by number
  Real mean_cube() const { return mean_cube_; }  ///< m^3, of d^3 by number: a ball's volume is pi/6 of it
  /// The diameter (m) at quantile u in [0, 1) of the number distribution.
  Real diameter(Real u) const;
  /// The fraction by mass finer than d (m).
  Real passing(Real d) const;
  /// The fraction by number finer than d (m).
  Real number_passing(Real d) const;

 private:
  SizeLaw law_;
  Real dmin_ = 0, dmax_ = 0, mean_ = 0, mean_cube_ = 0;
  Real median_n_ = 0, sd_ = 0, zlo_ = 0, zhi_ = 0;  // lognormal by number: ln(d / median_n) / sd in [zlo, zhi]
  Real plo_ = 0, pspan_ = 1;                        // Phi(zlo) and Phi(zhi) - Phi(zlo): the cut's quantiles
  std::vector<Real> sieve_, passing_, count_;       // sieve: count_[i] the number fraction finer than sieve_[i]
};

/// The balls' sizes in words for a job's description: "2 mm", "1.6 to 2.4 mm (uniform)", or the law with its range
/// and mean ("lognormal by mass, D50 2 mm, log_sd 0.1: 1.48 to 2.7 mm, mean 1.95 mm").
std::string size_text(const ParticleConfig& pc);

/// The text of a non-uniform distribution for keys (the specimen cache's), with a leading space: its law and
/// parameters; "" for uniform, so that the keys of earlier specimens hold.
std::string size_key(const ParticleConfig& pc);

}  // namespace dem
