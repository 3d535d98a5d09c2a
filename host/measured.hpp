#pragma once
/// Measured triaxial data (issue 5): a CSV of laboratory results per material and confining pressure,
/// either curves (eps_a, q, eps_v against axial strain) or summary points (q_peak, eps_a at peak, q at the
/// end, maximum dilatancy), with the unit in each column name. Parsed into SI; every error names the file,
/// the line and the column.
///
/// Columns (a header line; lines starting with '#' are comments):
///   material            text, e.g. S-1
///   sigma3_<unit>       confining pressure: kPa, MPa or Pa
///   curves:   eps_a_<u>, q_<stress unit>, and optionally eps_v_<u>   (strain units: pct or frac)
///   summary:  q_peak_<stress unit>, and optionally eps_a_peak_<u>, q_end_<stress unit>, max_dilatancy
/// A file is a curve file when it has an eps_a column, a summary file when it has q_peak. Within a curve
/// the axial strain must increase; a material and pressure appear once in a summary file.
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "kernels/vec3.hpp"

namespace dem {

/// A measured-data error: what() reads "<file>:<line>:<column name>: problem".
struct DataError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// One test (material, sigma3). Curve vectors are empty in a summary file; NaN marks a summary value the
/// file does not give.
struct MeasuredTest {
  std::string material;
  Real sigma3 = 0;                          ///< Pa
  std::vector<Real> eps_a, q, eps_v;        ///< fractions, Pa, fractions (compression / contraction positive)
  Real q_peak = 0, eps_a_peak = 0, q_end = 0, max_dilatancy = 0;  ///< Pa, -, Pa, -
};

struct MeasuredData {
  std::string path;
  bool curves = false;                      ///< curve file (else summary)
  std::vector<MeasuredTest> tests;          ///< in file order of first appearance
};

/// Reads and validates a measured-data CSV. Throws DataError.
MeasuredData load_measured(const std::string& path);

/// Fills the summary values of curve tests from their curves (q_peak and its strain, q at the last strain,
/// maximum of -d eps_v / d eps_a).
void summarise(MeasuredTest& t);

/// Refuses a test whose pressure is not among `sigma3` (Pa): names the file, the material and the pressure.
void check_pressures(const MeasuredData& d, const std::vector<Real>& sigma3);

}  // namespace dem
