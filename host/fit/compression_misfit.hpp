#pragma once
/// The misfit of compression tests (host/data/compression_data.hpp) fitted beside a material's triaxial tests: an
/// oedometer's or an isotropic compression's strain pins the contact stiffness, which the triaxial test's peak hardly
/// sees. Compared per test: the strain's increment between successive rows (a lab's strain is cumulative, so its rows
/// share their earlier increments' scatter; the increments are about independent) and K0 where the data give it.
/// Each datum whitened by
///   var = data_sd^2 + (1 + 1/K) var_specimens nu / (nu - 2),   nu = S - 1
/// data_sd from the file's standard deviations (an increment's from its two rows'), var_specimens the variance over
/// the S scatter specimens at the base model: the measured specimen is one specimen as variable as one of the
/// simulator's (the triaxial misfit's stance without a particle count), the compared mean of K members adds 1/K of
/// it, and an estimated variance is inflated as the triaxial misfit inflates it (host/fit/misfit.hpp). Its floor,
/// kCompressionFloor of the measured increment, stands where the specimens happen to agree.
#include <string>
#include <vector>

#include "host/fit/calibrate.hpp"
#include "host/lab/periodic_lab.hpp"

namespace dem {

/// Simulated compression tests of an ensemble: [test][member].
using CompressionEnsemble = std::vector<std::vector<CompressionTest>>;

/// The least standard deviation of a compared datum as a share of its measured value: two specimens of one packing
/// procedure do not compress within 1% of each other.
constexpr Real kCompressionFloor = 0.01;

class CompressionMisfit {
 public:
  /// `scatter`: the tests run at the base model on the S >= 4 scatter specimens; `members`: the ensemble whose mean is
  /// compared. Throws std::invalid_argument where there are fewer specimens.
  CompressionMisfit(const std::vector<CompressionTest>& measured, const CompressionEnsemble& scatter, int members);
  int data() const { return static_cast<int>(measured_value_.size()); }
  /// Whitened residuals, in test order: each test's increments, then its K0s; a datum the runs could not give is
  /// kMissingResidual.
  std::vector<Real> residuals(const CompressionEnsemble& sim) const;
  /// The term a calibration fits with its triaxial tests: these data, run on `lab`'s ensemble at each model.
  JointTerm joint(PeriodicLab& lab) const;
  /// Measured against simulated (the members' mean) per row, the cumulative strain and K0, as CSV (kPa, %).
  std::string table(const CompressionEnsemble& sim) const;
  const std::vector<CompressionTest>& measured() const { return measured_; }

 private:
  std::vector<CompressionTest> measured_;
  /// Per datum, in residual order: the measured value and its standard deviation.
  std::vector<Real> measured_value_, sd_;
  /// The data's values of a simulated test set, in residual order (the members' mean; NaN where one is missing).
  std::vector<Real> values(const CompressionEnsemble& sim) const;
};

/// The data's compared values of one test: its strain increments, then its K0s where `with_k0`.
std::vector<Real> compression_values(const CompressionTest& t, bool with_k0);

}  // namespace dem
