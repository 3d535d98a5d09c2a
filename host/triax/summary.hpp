#pragma once
/// What one drained triaxial test leaves for others to read: its headline numbers in OUT/summary.csv (written by
/// the membrane test and the periodic cell, read back by a study), and the plots drawn by the Python tools.
#include <string>
#include <vector>

#include "host/data/measured.hpp"
#include "host/config/provenance.hpp"

namespace dem {

/// The headline numbers of one drained triaxial test (SI inside; the CSV speaks kPa, %, deg).
struct TestSummary {
  std::string kind;             ///< "membrane" or "periodic"
  Real sigma3 = 0;              ///< Pa
  Real mu_s = 0, mu_r = 0;      ///< ball-ball friction of the test
  long balls = 0;
  Real void_ratio0 = 0;         ///< at the start of shear
  Real q_peak = 0;              ///< Pa, peak of the moving mean of q (summarise, host/data/measured.hpp)
  /// Pa, the same peak of the other measures of q (TriaxialRecord; docs/running.md, "Which q"): equal to q_peak
  /// in a periodic cell, which has no boundary; NaN in a summary written before they were recorded.
  Real q_peak_area = 0, q_peak_parabolic = 0, q_peak_membrane = 0, q_peak_lw = 0;
  Real phi_peak_deg = 0;        ///< asin(q / (q + 2 sigma3)) at the peak
  Real eps_a_peak = 0;          ///< axial strain at the peak
  Real q_end = 0;               ///< Pa, mean q over the last 1% of strain
  Real eps_a_end = 0;
  Real max_dilatancy = 0;       ///< max of -d eps_v / d eps_a
  Real inertial_number = 0;
  double wall_seconds = 0;
  Provenance provenance;        ///< empty in a summary written before it was recorded
};

struct Config;
struct TriaxialResult;
struct PeriodicTriaxialResult;

/// The summary of a membrane test of `balls` balls run from `cfg` (kind "membrane", each q measure's peak).
TestSummary summary_of(const Config& cfg, const TriaxialResult& r, long balls);
/// The summary of a cell's test of `balls` balls run from `cfg` (kind "periodic" or "walls"): the cell has one q,
/// the periodic cell's from its contacts, the walled cell's from its walls, so every measure's peak is q_peak.
TestSummary summary_of(const Config& cfg, const PeriodicTriaxialResult& r, long balls);

/// The peak of the q a lab reports as `m`, so that a measured peak is compared like with like; a periodic
/// cell's q_peak whatever m is.
Real q_peak_as(const TestSummary& s, QMeasure m);

/// Writes folder/summary.csv atomically (a header line and one row).
void write_summary(const std::string& folder, const TestSummary& s);
/// Reads it back; throws std::runtime_error naming the file and the missing column.
TestSummary read_summary(const std::string& path);

/// Recomputes the curve values of s (q_peak, its strain and friction angle, q_end, max dilatancy, and the
/// peaks of the other measures of q where the series has them) from folder/series.csv as summarise does
/// (s.sigma3 must be set). False, s unchanged, when the file is missing or lacks the eps_a_pct, q_kPa and
/// eps_v_pct columns.
bool summarise_series(const std::string& folder, TestSummary& s);

/// summary.csv's header line and a test's row in it (a study's table repeats them after its own columns).
std::string summary_header();
std::string summary_values(const TestSummary& s);

/// Runs tools/<script> with python3 on `args` (found beside the executable or in the source tree). Returns
/// false, after saying why on stderr, when python3, matplotlib or the script is missing: plots are extras.
bool run_plot_script(const std::string& script, const std::vector<std::string>& args);

}  // namespace dem
