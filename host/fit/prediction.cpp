#include "host/fit/prediction.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <stdexcept>

#include "host/fit/calibrate.hpp"
#include "host/lab/run_store.hpp"
#include "host/util/forked_runs.hpp"
#include "host/util/progress.hpp"
#include "host/triax/specimen.hpp"
#include "host/util/text_format.hpp"
#include "host/triax/triaxial.hpp"

namespace dem {

void check_prediction_template(const Config& membrane, const std::string& key) {
  if (!membrane.has_specimen)
    throw ConfigError(membrane.path + ": " + key + ": not a membrane test (no [specimen] table; a config of "
                      "configs/small/ or configs/paper/ is one)");
  const Real least = kMinDiametersAcross * membrane.particles.diameter;
  if (membrane.specimen.diameter < least)
    throw ConfigError(membrane.path + ": [specimen] diameter_mm: " + fmt("%g", 1e3 * membrane.specimen.diameter) +
                      " mm is " + fmt("%.1f", membrane.specimen.diameter / membrane.particles.diameter) +
                      " particle diameters across; a membrane test for " + key + " needs at least " +
                      fmt("%g", kMinDiametersAcross) + " (" + fmt("%g", 1e3 * least) + " mm)");
}

bool predicts_walls(const Config& base, const std::string& cli) {
  return (cli.empty() ? base.calibrate.predict : cli) == kPredictWalls;
}

std::optional<Config> prediction_template(const Config& base, const std::string& cli) {
  if (cli == "none" || (cli.empty() && base.calibrate.predict.empty()) || predicts_walls(base, cli))
    return std::nullopt;
  const std::string key = cli.empty() ? base.path + ": [calibrate] predict" : "--predict";
  const std::string path = cli.empty() ? (std::filesystem::path(base.path).parent_path() / base.calibrate.predict)
                                             .lexically_normal()
                                             .string()
                                       : cli;
  if (!std::filesystem::exists(path)) throw ConfigError(key + ": " + path + " does not exist (a membrane test's config)");
  Config c = load_config(path);
  check_prediction_template(c, key);
  return c;
}

Config prediction_config(const Config& membrane, const Model& calibrated, const std::vector<std::string>& free,
                         Real sigma3, int member) {
  Config c = membrane;
  Model ball{membrane.ball, 0}, wall{membrane.wall, 0};
  for (const std::string& name : free) {
    if (!is_contact_param(name)) continue;
    const Real v = get_param(calibrated, name);
    // The walls follow the balls' law where the template gives them none of their own ([wall_material]).
    if (get_param(wall, name) == get_param(ball, name)) set_param(wall, name, v);
    set_param(ball, name, v);
  }
  c.ball = ball.law;
  c.wall = wall.law;
  c.triaxial.sigma3 = sigma3;
  c.run.seed = membrane.run.seed + static_cast<unsigned>(member);
  return c;
}

std::vector<Prediction> predict(const Config& membrane, const Model& calibrated, const std::vector<std::string>& free,
                                const std::vector<TriaxialTest>& tests, QMeasure measure, int specimens,
                                const std::string& cache, bool verbose, int workers) {
  const int at_once = std::min(runs_at_once(workers), specimens);
  Ensemble runs(tests.size(), std::vector<TriaxialTest>(static_cast<std::size_t>(specimens)));
  Progress progress("prediction: membrane tests" + (at_once > 1 ? ", " + std::to_string(at_once) + " specimens at once" : std::string()),
                    static_cast<long>(tests.size() * specimens));
  long done = 0;
  auto ran = [&](int k, std::size_t j) {
    TriaxialTest& t = runs[j][static_cast<std::size_t>(k)];
    t.material = tests[j].material;
    t.replicate = std::to_string(k + 1);
    if (verbose)
      progress.update(++done, t.material + " at " + fmt("%g kPa", 1e-3 * t.sigma3) + ", specimen " + t.replicate +
                                  ": q_peak " + fmt("%.1f kPa", 1e-3 * t.q_peak));
  };
  // Specimen k's tests (friction and pressure do not change the specimen: one packing per member serves them all).
  auto run_specimen = [&](int k, bool say) {
    if (say) std::printf("prediction: specimen %d of %d (packed once, then cached in %s)\n", k + 1, specimens,
                         cache.c_str());
    const Specimen sp = cached_specimen(prediction_config(membrane, calibrated, free, membrane.triaxial.sigma3, k),
                                        cache, say);
    for (std::size_t j = 0; j < tests.size(); ++j) {
      const Config c = prediction_config(membrane, calibrated, free, tests[j].sigma3, k);
      const TriaxialResult r = run_triaxial(c, sp, nullptr, false);
      TriaxialTest& t = runs[j][static_cast<std::size_t>(k)];
      t = curves_of(r, q_field(measure), c.triaxial.sigma3);
      t.void_ratio = r.void_ratio_consolidated;
      t.specimen_balls = static_cast<Real>(sp.balls.size());
      if (at_once <= 1) ran(k, j);
    }
  };
  if (at_once <= 1) {
    for (int k = 0; k < specimens; ++k) run_specimen(k, verbose);
  } else {
    // Each specimen's build and tests in a child; its tests come back as curves (summarised again as curves_of
    // summarised them) with the specimen's balls.
    forked_runs(
        static_cast<std::size_t>(specimens), at_once,
        [&](std::size_t k, int fd) {
          run_specimen(static_cast<int>(k), false);
          for (std::size_t j = 0; j < tests.size(); ++j) {
            send_curves(fd, runs[j][k]);
            put_bytes(fd, &runs[j][k].specimen_balls, sizeof(Real));
          }
        },
        [&](std::size_t k, int fd) {
          for (std::size_t j = 0; j < tests.size(); ++j) {
            TriaxialTest& t = runs[j][k];
            t.sigma3 = tests[j].sigma3;
            if (!receive_curves(fd, t) || !get_bytes(fd, &t.specimen_balls, sizeof(Real))) return false;
            ran(static_cast<int>(k), j);
          }
          return true;
        },
        "membrane test",
        // A specimen's build and its tests take minutes before its first result: the line says they run.
        [&](std::size_t) {
          if (verbose) progress.update(done, "running: each specimen's build, then its tests");
        });
  }
  if (verbose) progress.finish("");
  return predictions_of(tests, std::move(runs));
}

std::vector<Prediction> predictions_of(const std::vector<TriaxialTest>& tests, Ensemble runs) {
  if (runs.size() != tests.size()) throw std::logic_error("predictions_of: runs for other tests than those given");
  std::vector<Prediction> out(tests.size());
  for (std::size_t j = 0; j < tests.size(); ++j) {
    out[j].measured = tests[j];
    out[j].members = std::move(runs[j]);
  }
  for (Prediction& p : out) {
    Real sum = 0, sum2 = 0;
    for (const TriaxialTest& t : p.members) sum += t.q_peak;
    const Real n = static_cast<Real>(p.members.size());
    p.q_peak_mean = sum / n;
    for (const TriaxialTest& t : p.members) sum2 += (t.q_peak - p.q_peak_mean) * (t.q_peak - p.q_peak_mean);
    p.q_peak_sd = n > 1 ? std::sqrt(sum2 / (n - 1)) : 0;
    p.error = (p.q_peak_mean - p.measured.q_peak) / p.measured.q_peak;
  }
  return out;
}

std::vector<Prediction> predict_walls(const Config& walls, const Model& calibrated,
                                      const std::vector<TriaxialTest>& tests, int specimens, int workers) {
  PeriodicLab lab(walls, false, specimens, walls.run.seed, specimens, workers);
  lab.set_progress("prediction: walled cells");
  Ensemble runs = lab.run_ensemble(calibrated, tests);
  for (std::size_t j = 0; j < tests.size(); ++j)
    for (std::size_t k = 0; k < runs[j].size(); ++k) {
      runs[j][k].material = tests[j].material;
      runs[j][k].replicate = std::to_string(k + 1);
    }
  return predictions_of(tests, std::move(runs));
}

namespace {

/// Mean and largest |error| over the predictions.
/// Mean and largest |error| over the tests the calibration fitted (held-out ones apart).
std::pair<Real, Real> error_summary(const std::vector<Prediction>& p) {
  Real sum = 0, most = 0;
  int n = 0;
  for (const Prediction& x : p) {
    if (x.held_out) continue;
    sum += std::fabs(x.error);
    most = std::max(most, std::fabs(x.error));
    ++n;
  }
  return {n == 0 ? 0 : sum / n, most};
}

/// The boundary's share of the predicted q: (membrane test - periodic cell) / membrane test; NaN without a cell.
Real boundary_share(const Prediction& x) { return (x.q_peak_mean - x.periodic_q_peak) / x.q_peak_mean; }

}  // namespace

std::string prediction_markdown(const std::vector<Prediction>& p, QMeasure measure) {
  std::string md = std::string("| material | sigma3 kPa | measured q_peak kPa | predicted kPa (mean +- sd of ") +
                   std::to_string(p.empty() ? 0 : p.front().members.size()) +
                   " specimens) | error | periodic cell kPa | boundary's share |\n|---|---|---|---|---|---|---|\n";
  for (const Prediction& x : p) {
    const bool cell = std::isfinite(x.periodic_q_peak);
    md += "| " + x.measured.material + " | " + fmt("%g", 1e-3 * x.measured.sigma3) + (x.held_out ? " (held out)" : "") +
          " | " +
          fmt("%.1f", 1e-3 * x.measured.q_peak) + " | " + fmt("%.1f", 1e-3 * x.q_peak_mean) + " +- " +
          fmt("%.1f", 1e-3 * x.q_peak_sd) + " | " + fmt("%+.1f%%", 100 * x.error) + " | " +
          (cell ? fmt("%.1f", 1e-3 * x.periodic_q_peak) : "-") + " | " +
          (cell ? fmt("%.0f%%", 100 * boundary_share(x)) : "-") + " |\n";
  }
  const auto [mean, most] = error_summary(p);
  md += "\nq as the data report it: " + std::string(name_of(measure)) + ". Mean |error| " + fmt("%.1f%%", 100 * mean) +
        ", at most " + fmt("%.1f%%", 100 * most) + " over the fitted tests.";
  for (const Prediction& x : p)
    if (x.held_out)
      md += " Held out (never fitted): " + x.measured.material + fmt(" at %g kPa", 1e-3 * x.measured.sigma3) +
            fmt(", %+.1f%%.", 100 * x.error);
  Real low = std::numeric_limits<Real>::infinity(), high = -low;
  for (const Prediction& x : p)
    if (std::isfinite(x.periodic_q_peak)) low = std::min(low, boundary_share(x)), high = std::max(high, boundary_share(x));
  if (low <= high)
    md += " The boundary's share of the predicted q_peak is " +
          (fmt("%.0f", 100 * low) == fmt("%.0f", 100 * high) ? fmt("%.0f%%", 100 * high)
                                                              : fmt("%.0f", 100 * low) + " to " + fmt("%.0f%%", 100 * high)) +
          ": what the test's boundary adds to what the grains carry, which a calibration "
          "on the periodic cell against such data puts into the contact parameters.";
  return md + "\n";
}

std::string prediction_csv(const std::vector<Prediction>& p, QMeasure measure) {
  std::string csv = "material,sigma3_kPa,q_measure,measured_q_peak_kPa,predicted_q_peak_kPa,predicted_sd_kPa,"
                    "specimens,error_pct,periodic_q_peak_kPa,boundary_share_pct,held_out\n";
  for (const Prediction& x : p) {
    const bool cell = std::isfinite(x.periodic_q_peak);
    csv += x.measured.material + "," + fmt("%g", 1e-3 * x.measured.sigma3) + "," + name_of(measure) + "," +
           fmt("%.6g", 1e-3 * x.measured.q_peak) + "," + fmt("%.6g", 1e-3 * x.q_peak_mean) + "," +
           fmt("%.6g", 1e-3 * x.q_peak_sd) + "," + std::to_string(x.members.size()) + "," +
           fmt("%.3f", 100 * x.error) + "," + (cell ? fmt("%.6g", 1e-3 * x.periodic_q_peak) : "") + "," +
           (cell ? fmt("%.3f", 100 * boundary_share(x)) : "") + "," + (x.held_out ? "1" : "0") + "\n";
  }
  return csv;
}

std::string membrane_test_text(const Config& membrane) {
  const long across = static_cast<long>(membrane.specimen.diameter / membrane.particles.diameter);
  return "The membrane test of " + membrane.path + " (" + std::to_string(across) + " particle diameters across, q "
         "at its platens as a lab measures it)";
}

std::string walled_cell_text(const Config& walls) {
  return "The cell of " + walls.path + " between six walls (" + std::to_string(walls.particles.count) +
         " balls prepared to the data's state, every stress a wall's force over its face, as a walled test measures "
         "it)";
}

std::string prediction_section(const std::string& test, long specimens, QMeasure measure, const std::string& markdown,
                               const std::string& discrepancy) {
  return "## Prediction: the test with a boundary\n\nThe calibration's periodic cell measures the grains inside a "
         "specimen, free of any boundary; the data were measured at a boundary (q as " + std::string(name_of(measure)) +
         "). " + test + ", run at each material's calibrated parameters and each pressure of the data, on " +
         std::to_string(specimens) + " specimens (prediction.csv, prediction_curves.csv):\n\n" + markdown +
         (discrepancy.empty() ? "" : "\nTwo fidelities: the periodic cell was calibrated again to the data less the "
                                     "membrane test's excess over it, measured at the last optimum, round by round "
                                     "until the optimum stopped moving:\n\n" + discrepancy) +
         "\n![predicted tests beside the data](prediction.png)\n";
}

}  // namespace dem
