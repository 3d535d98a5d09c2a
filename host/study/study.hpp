#pragma once
/// A set of triaxial cases run as one study (`triaxdem study configs/paper/`): each config a child process of
/// this program (in parallel where the machine has cores to spare), then one summary table and one figure.
/// Each test job leaves a summary.csv in its output folder (write_summary); the study reads them back.
#include <string>
#include <vector>

#include "host/config/config.hpp"
#include "host/data/measured.hpp"
#include "host/config/provenance.hpp"
#include "host/triax/summary.hpp"

namespace dem {

/// One case of a study: the config, which job runs it, and where its output goes.
struct StudyCase {
  std::string config;           ///< path of the TOML file
  std::string name;             ///< file stem, also the output subfolder
  std::string job;              ///< "triaxial" ([specimen] + [triaxial]) or "periodic" ([periodic])
  std::string material;         ///< [run] material ("" when the config names none)
  /// The case's work relative to the others', from its config (study_case_cost): the study starts the longest first.
  double cost = 0;
};

/// A case's work in arbitrary units, for the order the cases start in: balls times the shear's steps, which at one
/// ball size and stiffness go as the strain to reach over the inertial number times sqrt(sigma3) (the strain rate
/// is I sqrt(sigma3 / rho) / d). The specimen's packing, which grows with the balls alone, rides on the balls.
double study_case_cost(const Config& cfg);

/// The cases of `inputs` (folders, whose *.toml files are taken in name order, or single files). Every file
/// is validated first; one that describes no triaxial test is refused with its name and why.
std::vector<StudyCase> study_cases(const std::vector<std::string>& inputs);

struct StudyOptions {
  std::string output = "out/study";  ///< the summary and one subfolder per case
  int workers = 0;                   ///< cases run at once; 0: one per two cores (at least one)
  int threads = 0;                   ///< OpenMP threads per case; 0: the cores shared out among the workers
  bool resume = false;               ///< skip the cases with a summary.csv; continue those with a checkpoint.h5
  std::vector<std::string> compare;  ///< measured-data files whose peaks are set beside the cases'
};

/// The cases' peaks beside one measured-data file's: a case is matched by its [run] material and sigma3.
struct PeakComparison {
  std::string source;                ///< the file
  QMeasure measure = QMeasure::kFixedArea;  ///< the file's q, which the cases' q_peak_as matches
  std::vector<Real> measured;        ///< Pa, per case; NaN where the file has no such test or the case failed
  std::vector<Real> error;           ///< (simulated - measured) / measured, per case; NaN where unmatched
  int matched = 0;
  Real mean_abs_error = 0, max_abs_error = 0;  ///< over the matched cases
  std::size_t worst = 0;             ///< case of the largest |error|
};

/// Compares `summaries` (one per case, q_peak NaN for a failed case) with `data`'s q_peak.
PeakComparison compare_peaks(const MeasuredData& data, const std::vector<StudyCase>& cases,
                             const std::vector<TestSummary>& summaries);

/// What a study has so far: each case's summary (q_peak NaN unless it finished), the comparisons, and the
/// text of study_summary.csv, where a case not finished yet reads "pending" and a failed one "failed".
struct StudyTable {
  std::vector<TestSummary> summaries;
  std::vector<bool> ok;
  std::vector<PeakComparison> cmp;
  std::string csv;
};

/// The table from the cases' summary.csv files under `output`; status per case: -1 not finished yet, 0
/// finished, other values the exit status of a failed case. A finished case's curve values are taken afresh
/// from its series.csv (a kept case may come from a program that summarised differently), and its
/// summary.csv follows.
StudyTable study_table(const std::vector<StudyCase>& cases, const std::vector<int>& status, const std::string& output,
                       const std::vector<MeasuredData>& compare);

}  // namespace dem
