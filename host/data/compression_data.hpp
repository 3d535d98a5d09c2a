#pragma once
/// Measured compression tests: the strain an oedometer (one-dimensional loading) or an isotropic compression reached
/// at each stress a lab applied, from a CSV whose `test_type` column names the test. Parsed into SI; every error
/// names the file, the line and the column.
///
/// Columns (a header line; lines starting with '#' are comments):
///   material          text, e.g. S-1
///   test_type         oedometer or isotropic
///   sigma3_<unit>     the seating stress the specimen was consolidated to before loading (kPa, MPa or Pa), the same
///                     on every row of a test
///   stress_<unit>     the increment's target: the axial stress (oedometer) or the mean stress (isotropic)
///   strain_<unit>     the strain reached there, counted from the seating state (pct or frac): axial (oedometer),
///                     volumetric (isotropic); compression positive
///   optional: strain_sd_<unit> (each row's standard deviation, on every row or none), K0 (oedometer: sigma_h /
///             sigma_v at the row), K0_sd
/// A test is the rows of one material, test_type and sigma3, in file order: the increments in the order applied
/// (loading and unloading as the lab went).
#include <limits>
#include <string>
#include <vector>

#include "kernels/core/vec3.hpp"

namespace dem {

enum class CompressionPath { oedometer, isotropic };

/// "oedometer" or "isotropic".
const char* path_name(CompressionPath path);
/// The path of a name; throws std::invalid_argument naming the allowed ones.
CompressionPath compression_path(const std::string& name);

/// One compression test, measured or simulated at the measured one's stresses.
struct CompressionTest {
  std::string material;
  CompressionPath path = CompressionPath::oedometer;
  Real sigma3 = 0;                         ///< Pa, the seating stress
  std::vector<Real> stress;                ///< Pa, each increment's target
  std::vector<Real> strain;                ///< from the seating state: axial (oedometer) or volumetric (isotropic)
  std::vector<Real> k0;                    ///< sigma_h / sigma_v per increment (empty: not given)
  std::vector<Real> strain_sd, k0_sd;      ///< each row's standard deviation (empty: not given)
};

/// Reads and checks a compression file (CSV). Throws DataError naming the file, the line and the column.
std::vector<CompressionTest> load_compression(const std::string& path);

/// Tests as a compression file load_compression reads (kPa, %; K0 where every test gives it).
std::string compression_csv(const std::vector<CompressionTest>& tests);

/// "S-1 oedometer from 100 kPa" for messages and reports.
std::string describe(const CompressionTest& t);

}  // namespace dem
