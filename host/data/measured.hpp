#pragma once
/// Measured triaxial data: a CSV of laboratory results per material and confining pressure,
/// either curves (eps_a, q, eps_v against axial strain) or summary points (q_peak, eps_a at peak, q at the
/// end, maximum dilatancy), with the unit in each column name. Parsed into SI; every error names the file,
/// the line and the column.
///
/// Columns (a header line; lines starting with '#' are comments):
///   material            text, e.g. S-1
///   sigma3_<unit>       confining pressure: kPa, MPa or Pa
///   curves:   eps_a_<u>, q_<stress unit>, and optionally eps_v_<u>   (strain units: pct or frac)
///   summary:  q_peak_<stress unit>, and optionally eps_a_peak_<u>, q_end_<stress unit>, max_dilatancy,
///             e_ini_<stress unit> (initial stiffness dq/deps_a over the first 0.2% of axial strain),
///             q_1pct_<stress unit>, q_3pct_<stress unit> (q at 1% and 3% axial strain)
///   optional, either kind:
///     <quantity>_sd_<unit>   the standard deviation of a column (q_sd_kPa, eps_v_sd_pct, q_peak_sd_kPa,
///                            max_dilatancy_sd): on every row of a test or on none, > 0
///     void_ratio or porosity the specimen's state after consolidation (one value per test, repeated on its
///                            rows), with optional void_ratio_sd / porosity_sd
///     specimen_balls         particles in the specimen (DEM data), one value per test, >= 1
///     test                   a label that tells replicates apart: tests of one material and sigma3 with
///                            different labels are replicates (the scatter between them is measured noise)
///     q_measure              which deviator the lab reported, the same on every row (QMeasure: fixed_area,
///                            area_corrected, parabolic, membrane_corrected); without it fixed_area is taken
///                            and MeasuredData::notes says so. In HDF5: a string attribute q_measure on '/'.
/// A file is a curve file when it has an eps_a column, a summary file when it has q_peak. Within a curve
/// the axial strain must increase; a material, pressure and test label appear once in a summary file.
/// Implausible values are refused: |q| above kMaxStressRatio sigma3, a strain beyond kMaxStrain.
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "kernels/core/vec3.hpp"

namespace dem {

/// The most rows a test's curve and a file may have. The curve's smoothing and noise estimate read a window of rows
/// around each row, so their cost grows with the square of the rows per strain: 10^5 rows of a test take about a
/// second, 10^6 minutes. A curve shows nothing at 10^5 rows that it does not at 10^4. A file beyond the total is
/// refused while it is read, before it fills memory.
constexpr std::size_t kMaxCurveRows = 100000;
constexpr std::size_t kMaxFileRows = 2000000;

/// A measured-data error: what() reads "<file>:<line>:<column name>: problem".
struct DataError : std::runtime_error {
  using std::runtime_error::runtime_error;
  /// `at` is where in the file: "<path>:<line>" in a CSV, "<path>:/<material>/table row <k>" in HDF5.
  DataError(const std::string& at, const std::string& column, const std::string& what)
      : std::runtime_error(at + (column.empty() ? "" : ":" + column) + ": " + what) {}
};

/// Which deviator q a lab reports (docs/running.md, "Which q"): the platen force over the cross-section after
/// consolidation (the paper's), over the right-cylinder area A0 (1 - eps_v) / (1 - eps_a), over the mid-height
/// area of a parabolic barrel, or the right-cylinder value less what the membrane adds.
enum class QMeasure : int { kFixedArea = 0, kAreaCorrected, kParabolic, kMembraneCorrected };
constexpr int kQMeasures = 4;
/// Names in files and reports, by QMeasure.
constexpr const char* kQMeasureNames[kQMeasures] = {"fixed_area", "area_corrected", "parabolic", "membrane_corrected"};
inline const char* name_of(QMeasure m) { return kQMeasureNames[static_cast<int>(m)]; }

/// One drained triaxial test (material, sigma3), as a lab measured it or the simulator ran it: its curves and
/// summary. Curve vectors are empty in a summary file; NaN marks a summary value the file does not give.
struct TriaxialTest {
  std::string material;
  Real sigma3 = 0;                          ///< Pa
  std::vector<Real> eps_a, q, eps_v;        ///< fractions, Pa, fractions (compression / contraction positive)
  Real q_peak = 0, eps_a_peak = 0, q_end = 0, max_dilatancy = 0;  ///< Pa, -, Pa, -
  Real e_ini = 0;                           ///< Pa, initial stiffness dq/deps_a (first kInitialWindow of strain)
  Real q_1pct = 0, q_3pct = 0;              ///< Pa, q at kEarlyStrain and kMidStrain (NaN: the curve ends before)
  std::string replicate;                    ///< the file's `test` label ("" without one)
  std::vector<Real> q_sd, eps_v_sd;         ///< Pa, fractions: each row's standard deviation (empty: not given)
  std::map<std::string, Real> summary_sd;   ///< summary files: standard deviation by quantity (q_peak, ...), SI
  Real void_ratio = std::numeric_limits<Real>::quiet_NaN();     ///< after consolidation (NaN: not given)
  Real void_ratio_sd = std::numeric_limits<Real>::quiet_NaN();  ///< its standard deviation (NaN: not given)
  /// Particles in the measured specimen where the data say (DEM data; NaN: not given, as for a lab's): a
  /// specimen of N particles scatters from the next as N^-kSpecimenScatterExponent (host/fit/misfit.hpp).
  Real specimen_balls = std::numeric_limits<Real>::quiet_NaN();
};

struct MeasuredData {
  std::string path;
  bool curves = false;                      ///< curve file (else summary)
  std::vector<TriaxialTest> tests;          ///< in file order of first appearance
  QMeasure q_measure = QMeasure::kFixedArea;  ///< which q the file's q columns are
  bool q_measure_given = false;             ///< false: the file did not say (fixed_area taken, with a note)
  std::vector<std::string> notes;           ///< what the reader accepted but a user should know (near-equal pressures)
};

/// Limits of plausible data: |q| <= kMaxStressRatio sigma3, |strain| <= kMaxStrain (fractions).
constexpr Real kMaxStressRatio = 100, kMaxStrain = 1.0;
/// The least peak a drained test reaches, as a share of sigma3: q_peak / sigma3 = 2 sin phi / (1 - sin phi) is 0.05 at
/// a friction angle of 1.4 deg, below any granular material; a file under it holds sigma3 in Pa under a kPa header
/// (the peak 1000 times too small) or q in another unit.
constexpr Real kMinPeakRatio = 0.05;
/// Tests of one material whose sigma3 differ by less than this fraction are replicates of one pressure.
constexpr Real kReplicateTolerance = 0.02;

/// Groups of replicate tests (indices into tests): the same material, sigma3 within kReplicateTolerance; every
/// test is in exactly one group, groups in order of their first test.
std::vector<std::vector<std::size_t>> replicate_groups(const std::vector<TriaxialTest>& tests);

/// Reads and validates a measured-data file: CSV, or HDF5 (.h5, .hdf5) with the same columns: one group per
/// material holding a 2-D dataset `table` (rows x columns, numbers) whose string attribute `columns` names
/// the columns after `material`, comma-separated, units included (e.g. "sigma3_kPa,eps_a_pct,q_kPa,eps_v_pct").
/// Throws DataError naming the file, the line (CSV) or group and row (HDF5), and the column.
MeasuredData load_measured(const std::string& path);

/// The factor to SI of a column named "<quantity>_<unit>": a stress's unit (Pa, kPa, MPa) or a strain's (pct, frac).
/// Throws DataError naming `at`, the column and the allowed units.
Real column_scale(const std::string& at, const std::string& column, bool stress);

/// True for a path ending in .h5 or .hdf5: the HDF5 form of measured data.
bool is_hdf5_path(const std::string& path);

/// A measured-data file as text, before validation: the header and each row with where it is in the file.
struct MeasuredTextTable {
  struct Row {
    std::string at;                     ///< "<path>:<line>" or "<path>:/<material>/table row <k>"
    std::vector<std::string> cells;
  };
  std::string header_at;
  std::vector<std::string> header;
  std::vector<Row> rows;
};

/// A cell as written (inf and nan included); nothing when it is not a number.
std::optional<double> parse_number(const std::string& cell);

/// The lines of a CSV file as a table, cells trimmed; comment ('#') and blank lines skipped. Throws DataError
/// when the file cannot be read.
MeasuredTextTable read_csv_table(const std::string& path);

/// The HDF5 form as a table (host/data/measured_h5.cpp). Throws DataError.
MeasuredTextTable read_measured_h5(const std::string& path);

/// Writes measured data in the HDF5 form, atomically: `columns` after material (units in the names) and, per
/// material, its rows of numbers in those columns; `q_measure` (a kQMeasureNames entry) when not empty. Throws
/// DataError naming the path.
void write_measured_h5(const std::string& path, const std::vector<std::string>& columns,
                       const std::map<std::string, std::vector<std::vector<double>>>& rows,
                       const std::string& comment, const std::string& q_measure = "");

/// Strain windows of summarise: curves are smoothed by a moving mean over +-0.25% axial strain, q at the end
/// is the mean over the last 1%, the initial stiffness is fitted over the first 0.2% (the elastic range of
/// bead contacts, overlap / radius ~ 1e-3, lies within it).
constexpr Real kSmoothHalfWidth = 0.0025, kEndWindow = 0.01, kInitialWindow = 0.002;
/// The axial strains of the two points on the hardening curve (q_1pct, q_3pct).
constexpr Real kEarlyStrain = 0.01, kMidStrain = 0.03;

/// Fills the summary values of a curve test from its smoothed curves: q at 1% and 3% strain (interpolated
/// between rows), q_peak and its strain, q at the end,
/// the initial stiffness (least-squares slope of the raw rows over the first 0.2% of strain) and the maximum dilatancy
/// -d eps_v / d eps_a (the slope over one 0.5% window). The same function summarises simulated curves.
void summarise(TriaxialTest& t);

/// A simulated test's rows (any type with eps_a, q and eps_v) as a curve test, summarised like measured curves:
/// its peak is the peak of the moving mean, not the highest single row (rows of a full-scale specimen scatter
/// by about 4% of q), so that simulated and measured peaks compare like with like.
template <class Row>
TriaxialTest summarised(const std::vector<Row>& rows, Real sigma3) {
  TriaxialTest t;
  t.sigma3 = sigma3;
  for (const Row& r : rows) {
    t.eps_a.push_back(r.eps_a);
    t.q.push_back(r.q);
    t.eps_v.push_back(r.eps_v);
  }
  summarise(t);
  return t;
}

/// Peak friction angle (degrees) of a deviator q at confining pressure sigma3: asin(q / (q + 2 sigma3)).
Real friction_angle_deg(Real q, Real sigma3);

/// Copies a summarised test's curve values into a result with the same field names (q_peak, eps_a_peak,
/// phi_peak_deg, q_end, max_dilatancy), the friction angle from q_peak at the test's sigma3.
template <class Result>
void take_curve_values(Result& r, const TriaxialTest& t) {
  r.q_peak = t.q_peak;
  r.eps_a_peak = t.eps_a_peak;
  r.phi_peak_deg = friction_angle_deg(t.q_peak, t.sigma3);
  r.q_end = t.q_end;
  r.max_dilatancy = t.max_dilatancy;
}

/// Reference parameter values to set beside calibrated ones (e.g. a paper's own calibration): a CSV with a
/// `material` column and one column per parameter, named as in [calibrate] free (mu_s, mu_r, ...), in that
/// key's unit. Comment lines ('#') are kept as the source's description.
struct ReferenceValues {
  std::string path;
  std::string comment;                                          ///< the comment lines, joined
  std::vector<std::string> parameters;                          ///< column order
  std::map<std::string, std::map<std::string, Real>> values;    ///< material -> parameter -> value
};

/// Reads a reference file; `known` checks a parameter name and throws std::invalid_argument when it is not one.
/// Throws DataError naming the line and column.
ReferenceValues load_reference(const std::string& path, const std::function<void(const std::string&)>& known);

/// "material at 100 kPa, test b": a test as errors name it.
std::string describe_test(const TriaxialTest& t);

/// Refuses what no drained test shows, after its rows are read: a peak at or below zero (a sign flipped), a peak
/// under kMinPeakRatio sigma3 (a unit slipped), a volumetric strain zero on every row of a curve (not measured).
/// Throws DataError naming the file and the test.
void check_plausible(const std::string& path, const TriaxialTest& t, bool curves);

/// Refuses a test whose pressure is not among `sigma3` (Pa): names the file, the material and the pressure.
void check_pressures(const MeasuredData& d, const std::vector<Real>& sigma3);

}  // namespace dem
