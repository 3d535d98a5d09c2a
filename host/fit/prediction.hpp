#pragma once
/// The loop closed: a test with a boundary at calibrated parameters, at each pressure of the data, on a few
/// specimens, set beside the data in the q the data report (QMeasure). A calibration on the periodic cell says what
/// the grains do inside a specimen; this says what the lab's test would have measured with those grains: the
/// membrane triaxial test (host/triax/triaxial.hpp), membrane, platens and bulge included, or the cell between six walls
/// (host/triax/cell_boundary.hpp), its walls' layer and stress measure included.
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "host/config/config.hpp"
#include "host/data/measured.hpp"
#include "host/lab/periodic_lab.hpp"

namespace dem {

/// A membrane test must be this many particle diameters across: thinner, the membrane's bands and the walls'
/// layering make up most of the specimen (a packing is layered near a wall; 1 - (1 - 4 d / D)^2 of the
/// cross-section lies within two diameters of the lateral wall, 75% at 8 diameters across).
constexpr Real kMinDiametersAcross = 8;

/// The membrane test's config ([specimen] and [triaxial]) checked as a prediction's template: it must describe a
/// membrane test at least kMinDiametersAcross particles across. `key` names where it came from in messages.
/// Throws ConfigError naming the file, the key and the smallest allowed size.
void check_prediction_template(const Config& membrane, const std::string& key);

/// --predict's (and [calibrate] predict's) word for the cell between six walls instead of a membrane test.
inline const std::string kPredictWalls = "walls";

/// True where the calibration ends with the walled cell: `cli` says kPredictWalls, or it is empty and the base
/// config's [calibrate] predict does.
bool predicts_walls(const Config& base, const std::string& cli);

/// The membrane test a calibration ends with: `cli` (--predict's config), else the base config's [calibrate]
/// predict (relative to the base config's folder); none for "none", for kPredictWalls or where neither names one. Loaded and checked
/// (check_prediction_template) before any run; ConfigError names the key.
std::optional<Config> prediction_template(const Config& base, const std::string& cli);

/// The template with the calibrated contact parameters (`free` names, values from `calibrated`), the pressure
/// sigma3 (Pa) and packing seed [run] seed + member. Free parameters of the periodic cell alone (its membrane
/// extension) are left out: the membrane test has its own membrane.
Config prediction_config(const Config& membrane, const Model& calibrated, const std::vector<std::string>& free,
                         Real sigma3, int member);

/// One pressure of one material, predicted.
struct Prediction {
  TriaxialTest measured;               ///< the data's test
  std::vector<TriaxialTest> members;   ///< one per specimen, q in the data's measure, labelled by member
  Real q_peak_mean = 0, q_peak_sd = 0; ///< Pa, over the members (sd 0 with one)
  Real error = 0;                      ///< (q_peak_mean - measured q_peak) / measured q_peak
  /// Pa, the calibration's periodic cell at the same parameters and pressure (NaN: not given): the membrane
  /// test exceeds it by what its boundary (membrane, platens, bulge, walls) adds to the q the data report.
  Real periodic_q_peak = std::numeric_limits<Real>::quiet_NaN();
  bool held_out = false;               ///< a test the calibration left out (--hold-out): predicted, never fitted
};

/// One Prediction per test of `tests` from `runs` (one list of members per test): the members' mean q_peak and
/// its sample sd, and the error against the test's q_peak.
std::vector<Prediction> predictions_of(const std::vector<TriaxialTest>& tests, Ensemble runs);

/// Runs the template at `calibrated` for every test of `tests` on `specimens` specimens (packed once each, cached in
/// `cache`), q summarised in `measure`. Prints a progress line when `verbose`. `workers` > 1: the specimens side by
/// side, each with its tests in a child process, where that is safe (runs_at_once), with the same results, bit for
/// bit, as one at a time.
std::vector<Prediction> predict(const Config& membrane, const Model& calibrated, const std::vector<std::string>& free,
                                const std::vector<TriaxialTest>& tests, QMeasure measure, int specimens,
                                const std::string& cache, bool verbose, int workers = 1);

/// The cell between six walls of `walls` (a walled config: reference_cell(base, "walls"), its preparation matched)
/// at `calibrated` for every test of `tests`, on its first `specimens` specimens (packing seeds from [run] seed),
/// `workers` runs at once, with a progress line.
std::vector<Prediction> predict_walls(const Config& walls, const Model& calibrated,
                                      const std::vector<TriaxialTest>& tests, int specimens, int workers);

/// The predictions as a Markdown table (material, sigma3, measured and predicted q_peak with the members' scatter,
/// error; the periodic cell's q_peak and the boundary's share (predicted - periodic) / predicted where given) with
/// the mean and largest |error| over the fitted tests, each held-out test's error apart, and the range of the
/// boundary's share, and as CSV rows with a header.
std::string prediction_markdown(const std::vector<Prediction>& p, QMeasure measure);
std::string prediction_csv(const std::vector<Prediction>& p, QMeasure measure);

/// What a prediction runs, in words for the report: the membrane test of a template, with its size.
std::string membrane_test_text(const Config& membrane);
/// The same for the walled cell of `walls` (predict_walls).
std::string walled_cell_text(const Config& walls);

/// The report's section: what was run (`test`: membrane_test_text or walled_cell_text, on `specimens` specimens,
/// q as `measure`), the table `markdown` (prediction_markdown), the two-fidelity correction in words when
/// `discrepancy` is not empty, and prediction.png.
std::string prediction_section(const std::string& test, long specimens, QMeasure measure, const std::string& markdown,
                               const std::string& discrepancy);

}  // namespace dem
