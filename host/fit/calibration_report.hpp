#pragma once
/// The tables of `triaxdem calibrate` and `diagnose`: errors per test (like the paper's Table 6), calibrated values
/// with their intervals and a reference point's place. They read only the results they are handed; the diagnosis's
/// own tables (the noise used, an extension's gain) are its report's (host/study/diagnosis_report.cpp).
#include <string>
#include <vector>

#include "host/fit/calibrate.hpp"
#include "host/data/measured.hpp"
#include "host/fit/misfit.hpp"

namespace dem {

/// Measured, simulated and error per test and quantity, as CSV.
std::string errors_csv(const std::vector<TriaxialTest>& meas, const std::vector<TriaxialTest>& sim);
/// The same table on stdout.
void print_errors(const std::vector<TriaxialTest>& meas, const std::vector<TriaxialTest>& sim);
/// The calibrated values with their 95% intervals and correlations, in lines prefixed "<job>: <material>: ".
std::string uncertainty_text(const CalibrationResult& r, const std::string& material, const std::string& job);
/// Where a reference gives every free parameter (`reference`, in the keys' units): the reference point's place against
/// the joint 95% region, in a line prefixed "<job>: <material>: ": the surrogate chi2's rise there as a share of the
/// region's (at most 1 inside), and, where the point was run (`run_chi2` finite), its chi2 beside the best's.
std::string reference_text(const CalibrationResult& r, const std::vector<Real>& reference, Real run_chi2,
                           const std::string& material, const std::string& job);

}  // namespace dem
