#pragma once
/// The loop closed: the membrane triaxial test (host/triaxial.hpp) at calibrated parameters, at each pressure of
/// the data, on a few specimens, set beside the data in the q the data report (QMeasure). A calibration on the
/// periodic cell says what the grains do inside a specimen; this says what the lab's test would have measured
/// with those grains, membrane, platens and bulge included.
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "config.hpp"
#include "measured.hpp"
#include "periodic_lab.hpp"

namespace dem {

/// A membrane test must be this many particle diameters across: thinner, the membrane's bands and the walls'
/// layering make up most of the specimen (shared/notes/triaxial_measures.md, section 4).
constexpr Real kMinDiametersAcross = 8;

/// The membrane test's config ([specimen] and [triaxial]) checked as a prediction's template: it must describe a
/// membrane test at least kMinDiametersAcross particles across. `key` names where it came from in messages.
/// Throws ConfigError naming the file, the key and the smallest allowed size.
void check_prediction_template(const Config& membrane, const std::string& key);

/// The membrane test a calibration ends with: `cli` (--predict's config), else the base config's [calibrate]
/// predict (relative to the base config's folder); none for "none" or where neither names one. Loaded and checked
/// (check_prediction_template) before any run; ConfigError names the key.
std::optional<Config> prediction_template(const Config& base, const std::string& cli);

/// The template with the calibrated contact parameters (`free` names, values from `calibrated`), the pressure
/// sigma3 (Pa) and packing seed [run] seed + member. Free parameters of the periodic cell alone (its membrane
/// extension) are left out: the membrane test has its own membrane.
Config prediction_config(const Config& membrane, const Model& calibrated, const std::vector<std::string>& free,
                         Real sigma3, int member);

/// One pressure of one material, predicted.
struct Prediction {
  MeasuredTest measured;               ///< the data's test
  std::vector<MeasuredTest> members;   ///< one per specimen, q in the data's measure, labelled by member
  Real q_peak_mean = 0, q_peak_sd = 0; ///< Pa, over the members (sd 0 with one)
  Real error = 0;                      ///< (q_peak_mean - measured q_peak) / measured q_peak
  /// Pa, the calibration's periodic cell at the same parameters and pressure (NaN: not given): the membrane
  /// test exceeds it by what its boundary (membrane, platens, bulge, walls) adds to the q the data report.
  Real periodic_q_peak = std::numeric_limits<Real>::quiet_NaN();
};

/// Runs the template at `calibrated` for every test of `tests` on `specimens` specimens (packed once each, cached in
/// `cache`), q summarised in `measure`. Prints a progress line when `verbose`.
std::vector<Prediction> predict(const Config& membrane, const Model& calibrated, const std::vector<std::string>& free,
                                const std::vector<MeasuredTest>& tests, QMeasure measure, int specimens,
                                const std::string& cache, bool verbose);

/// The predictions as a Markdown table (material, sigma3, measured and predicted q_peak with the members' scatter,
/// error; the periodic cell's q_peak and the boundary's share (predicted - periodic) / predicted where given) with
/// the mean and largest |error|, and as CSV rows with a header.
std::string prediction_markdown(const std::vector<Prediction>& p, QMeasure measure);
std::string prediction_csv(const std::vector<Prediction>& p, QMeasure measure);

/// The report's section: what was run (`membrane` on `specimens` specimens, q as `measure`), the table
/// `markdown` (prediction_markdown), the two-fidelity correction in words when `discrepancy` is not empty, and
/// prediction.png.
std::string prediction_section(const Config& membrane, long specimens, QMeasure measure, const std::string& markdown,
                               const std::string& discrepancy);

}  // namespace dem
