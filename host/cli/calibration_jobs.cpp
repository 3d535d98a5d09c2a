#include "host/cli/calibration_jobs.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <map>
#include <optional>
#include <sstream>

#include "host/fit/calibrate.hpp"
#include "host/io/io_hdf5.hpp"
#include "host/fit/diagnose.hpp"
#include "host/fit/prediction.hpp"
#include "host/fit/two_fidelity.hpp"
#include "host/util/progress.hpp"
#include "host/fit/calibration_report.hpp"
#include "host/util/text_format.hpp"
#include "host/triax/summary.hpp"

namespace dem {

namespace fs = std::filesystem;

std::string new_dated_folder(const std::string& parent, const std::string& prefix) {
  const std::time_t now = std::time(nullptr);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", std::localtime(&now));
  fs::create_directories(parent);
  const std::string stem = (fs::path(parent) / (prefix + "_" + stamp)).string();
  for (int k = 1;; ++k) {
    const std::string path = k == 1 ? stem : stem + "-" + std::to_string(k);
    if (fs::create_directory(path)) return path;  // false: it exists; never reuse it
  }
}

namespace {

/// A folder as a path without a trailing separator ("out/calibrate_x/" names calibrate_x).
fs::path folder_path(const std::string& folder) {
  fs::path p = fs::path(folder).lexically_normal();
  return p.has_filename() ? p : p.parent_path();
}

/// The folder a resumed calibrate or diagnose continues in: one that a run of the same kind made.
std::string resumed_folder(const std::string& folder, const std::string& kind) {
  const std::string name = folder_path(folder).filename().string();
  if (!fs::is_directory(folder) || name.rfind(kind + "_", 0) != 0)
    throw std::invalid_argument("--resume " + folder + ": not a " + kind + "_<date> folder of an earlier " + kind +
                                " (it gives the folder to continue in)");
  return folder_path(folder).string();
}

/// The parent folder of a resumed folder: where its run left the specimens it shares with others.
std::string resumed_parent(const std::string& folder) {
  const fs::path parent = folder_path(folder).parent_path();
  return parent.empty() ? "." : parent.string();
}

/// The free parameters: from the command line, else from the config's [calibrate] free.
std::vector<FreeParam> free_params(const Config& cfg, const std::vector<std::string>& cli) {
  std::vector<FreeParam> out;
  for (const std::string& n : cli.empty() ? cfg.calibrate.free : cli) {
    // A parameter twice would be two coordinates of one value: a singular fit.
    for (const FreeParam& f : out)
      if (f.name == n)
        throw ConfigError((cli.empty() ? cfg.path + ": [calibrate] free" : std::string("--free")) + ": " + n +
                          " given twice (each free parameter once)");
    try {
      out.push_back(free_param(n, model_of(cfg)));
    } catch (const std::invalid_argument& e) {
      if (!cli.empty()) throw;
      throw ConfigError(cfg.path + ": [calibrate] free: " + e.what());
    }
  }
  return out;
}

/// The tests of the data by material (sorted by name), filtered by `only` when it is set.
std::map<std::string, std::vector<MeasuredTest>> by_material(const MeasuredData& d, const std::string& only) {
  std::map<std::string, std::vector<MeasuredTest>> out;
  for (const MeasuredTest& t : d.tests)
    if (only.empty() || t.material == only) out[t.material].push_back(t);
  if (out.empty()) throw DataError(d.path + ": no tests of material '" + only + "'");
  return out;
}

/// A material's calibration as the prediction needs it: its tests, the model, and the periodic cell's tests at it.
struct Calibrated {
  std::vector<MeasuredTest> tests;
  Model model;
  std::vector<MeasuredTest> sim;  ///< in the order of tests
};

/// Removes a result folder that is still empty when the job ends: a refusal after the folder was made.
struct EmptyFolderRemover {
  std::string path;
  EmptyFolderRemover(const EmptyFolderRemover&) = delete;
  EmptyFolderRemover& operator=(const EmptyFolderRemover&) = delete;
  ~EmptyFolderRemover() {
    std::error_code ec;
    if (fs::is_directory(path, ec) && fs::is_empty(path, ec)) fs::remove(path, ec);
  }
};

/// --predict walls, checked: the reference test must not be the walled cell already.
bool walls_prediction_wanted(const Config& base, const CalibrationOptions& o) {
  if (!predicts_walls(base, o.predict)) return false;
  if (reference_cell(base, o.reference_test).periodic.boundary == CellBoundary::walls)
    throw ConfigError((o.predict.empty() ? base.path + ": [calibrate] predict" : std::string("--predict")) +
                      ": walls: the reference test is the cell between six walls already; predict a membrane test "
                      "(a config of configs/small/) or none");
  return true;
}

/// What calibrate and diagnose share: the data, the free parameters, the simulator and a new result folder.
struct Session {
  MeasuredData data;
  ReferenceValues ref;
  std::vector<FreeParam> free;
  StateMatch state;  ///< the data's void ratio and the preparation that packs it
  std::optional<Config> predict_template;
  bool walls_prediction = false;  ///< the prediction is the reference cell between six walls (kPredictWalls)
  int jobs = 1;
  bool two_fidelity = false;  ///< the reference test: the periodic cell corrected by the membrane test
  std::string discrepancy;    ///< what the two fidelities measured, for the report
  PeriodicLab lab;
  std::string folder, output;
  EmptyFolderRemover remover{folder};
  Session(const Config& base, const CalibrationOptions& o, const std::string& kind)
      : data(load_measured(o.data)),
        ref(o.reference.empty() ? ReferenceValues{}
                                : load_reference(o.reference, [](const std::string& n) { free_param(n); })),
        free(free_params(base, o.free)), predict_template(prediction_template(base, o.predict)),
        walls_prediction(walls_prediction_wanted(base, o)), jobs(o.jobs),
        two_fidelity(two_fidelity_wanted(base, o.reference_test, predict_template.has_value())),
        lab(matched(reference_cell(base, o.reference_test), o.jobs), true, o.jobs),
        folder(o.resume.empty() ? new_dated_folder(o.output, kind) : resumed_folder(o.resume, kind)),
        output(o.resume.empty() ? o.output : resumed_parent(o.resume)) {
    lab.set_run_store(folder + "/runs");
    if (!o.resume.empty())
      std::printf("%s: resuming in %s: the runs stored there are read, not run again\n", kind.c_str(), folder.c_str());
    if (o.noise == "data" || o.noise == "lab") noise.mode = o.noise;
    else noise = lab_noise_options(o.noise);
    for (const std::string& n : data.notes) std::printf("%s: note: %s\n", kind.c_str(), n.c_str());
  }
  NoiseOptions noise;
  /// The reference test's cell, for the report.
  std::string cell_text() const {
    return lab.config().periodic.boundary == CellBoundary::walls
               ? "the cell between six walls (stresses measured at the walls, as a walled test measures them)"
               : "the periodic cell (stresses from its contacts: the specimen's interior, without a boundary)";
  }
  /// "N runs", how many of them a resumed session read from its store, and how many a blow-up stopped: their data
  /// count as missing (kMissingResidual), which pushes the fit away from where they happen.
  std::string runs_text() const {
    const long read = lab.stored_runs_read();
    return std::to_string(lab.runs()) + " runs" +
           (read > 0 ? " (" + std::to_string(read) + " of them read from the run store)" : "") +
           (lab.failed_runs() > 0 ? "; WARNING: " + failed_text() : "");
  }
  std::string failed_text() const {
    return std::to_string(lab.failed_runs()) + " of the runs stopped at a blow-up" +
           fmt(" (up to %g kPa)", 1e-3 * lab.highest_failed_sigma3()) +
           ", their data counted as missing: where the overlaps are the contacts' physics (soft contacts at high "
           "pressure), raise [solver] overlap_limit (docs/config.md)";
  }
  std::vector<std::string> free_names() const {
    std::vector<std::string> names;
    for (const FreeParam& f : free) names.push_back(f.name);
    return names;
  }
  /// The membrane test at `model` on every test of `tests`, q in the data's measure (a template must be set).
  std::vector<Prediction> predict_at(const Config& base, const Model& model, const std::vector<MeasuredTest>& tests) const {
    return predict(*predict_template, model, free_names(), tests, data.q_measure,
                   static_cast<int>(base.calibrate.predict_specimens), output + "/.specimens", true);
  }
  Config matched(const Config& base, int jobs) {
    return matched_state(base, data.tests, state, true, match_plan(base, jobs));
  }
  /// The report's line on the specimens' state.
  std::string state_text(const Misfit& m, const std::vector<MeasuredTest>& tests) const {
    if (state.tests == 0)
      return "The data give no void ratio: the simulator's specimens have the density their preparation gives (" +
             fmt("e = %.3f", lab.prepared_void_ratio(0)) + " for the first), and the calibrated friction absorbs "
             "any difference in density.\n";
    std::string s = "The simulator's specimens were prepared to the data's void ratio " + fmt("%.4f", state.target) +
                    " (preparation friction " + fmt("%.4g", state.prep_mu_s) + ", which packs " +
                    fmt("%.4f", state.reached) +
                    fmt(" on the mean of its first %.0f", static_cast<double>(state.specimens)) +
                    "). At the start of shear, measured and simulated (mean of the scatter specimens at the base "
                    "model):";
    for (std::size_t k = 0; k < tests.size(); ++k)
      s += fmt(" %g kPa", 1e-3 * tests[k].sigma3) + fmt(" %.4f", tests[k].void_ratio) +
           fmt(" against %.4f;", m.reached_void_ratio(k));
    return s + "\n";
  }
  /// The misfit of a material's tests: the ensemble run at the base model, its scatter beside the data's noise.
  Misfit misfit_of(const Config& base, const std::string& material, const std::vector<MeasuredTest>& tests) {
    std::printf("%s: %s: measuring the simulator's scatter: %d specimens of %zu balls at the base model\n",
                folder.c_str(), material.c_str(), lab.specimens(), lab.balls());
    lab.set_progress("  " + material + ": scatter");
    Misfit m = measure_misfit(lab, model_of(base), tests, noise, true, &state);
    lab.set_progress("");
    for (const std::string& n : m.notes()) std::printf("  noise: %s\n", n.c_str());
    const Real ratio = m.ensemble_ratio();
    const bool chosen = base.calibrate.ensemble == kAutoEnsemble;
    // An "auto" cell grows only with an "auto" ensemble: a fixed ensemble fixes the cost per point.
    const bool cell_chosen = chosen && base.calibrate.cell_factor == kAutoCell;
    std::printf("  cell: %zu balls, %d x the config's (%s)%s\n", lab.balls(), lab.cell_factor(),
                base.calibrate.cell_factor != kAutoCell ? "[calibrate] cell_factor" : cell_chosen ? "chosen" : "kept",
                lab.cell_factor() > 1 && cell_chosen ? ": all the scatter specimens of the config's cell fell short"
                                                     : "");
    std::printf("  ensemble: %d specimens per parameter point (%s); the simulator's standard error is %.2f of the "
                "data's noise (median)%s\n", lab.members(), chosen ? "chosen" : "[calibrate] ensemble", ratio,
                ratio > kEnsembleRatioGoal ? "" : ": below 1/2, enough");
    if (ratio > kEnsembleRatioGoal) {
      // The mean of K specimens of N balls scatters as 1 / sqrt(K N): where K runs out, N makes up the rest.
      const int k = m.members_for(kEnsembleRatioGoal);
      const Real grow = static_cast<Real>(k) / lab.specimens();
      const Real factor = std::ceil(grow * lab.cell_factor());
      const std::string beyond = cell_chosen && factor > kMaxCellFactor
                                     ? ", beyond the " + std::to_string(kMaxCellFactor) + " x an \"auto\" cell grows to"
                                     : "";
      std::printf("  WARNING: above 1/2, and the misfit counts it. %d specimens would bring it to 1/2", k);
      if (grow > 1)
        std::printf(" (scatter_specimens = %d), or all %d in a cell of about %.0f balls (cell_factor = %.0f%s)", k,
                    lab.specimens(), grow * static_cast<Real>(lab.balls()), factor, beyond.c_str());
      std::printf("\n");
    }
    return m;
  }
  /// The reference value of a parameter for a material, in the key's unit; NaN when there is none.
  Real reference(const std::string& material, const std::string& name) const {
    auto m = ref.values.find(material);
    if (m == ref.values.end()) return std::nan("");
    auto v = m->second.find(name);
    return v == m->second.end() ? std::nan("") : v->second;
  }
  /// The test with a boundary at each material's calibrated model (`models`, by material), beside the data: the
  /// membrane test of the template or the walled cell. Writes prediction.csv, prediction_curves.csv and
  /// prediction.png, prints the table, and returns it as Markdown ("" when there is no prediction).
  std::string predict_boundary(const Config& base, const std::map<std::string, Calibrated>& models) const {
    if (!predict_template && !walls_prediction) {
      std::printf("%s: no prediction ([calibrate] predict or --predict names a membrane test, or walls)\n",
                  folder.c_str());
      return "";
    }
    std::optional<Config> walls;
    if (walls_prediction) {
      StateMatch walls_state;  // the walled cell's own preparation to the data's state
      const Config cell = reference_cell(base, kPredictWalls);
      walls = matched_state(cell, data.tests, walls_state, true, match_plan(cell, jobs));
    }
    const std::string test = walls ? walled_cell_text(*walls) : membrane_test_text(*predict_template);
    const int specimens = static_cast<int>(base.calibrate.predict_specimens);
    std::vector<Prediction> all;
    std::vector<MeasuredTest> curves;
    for (const auto& [material, cal] : models) {
      const std::vector<MeasuredTest>& tests = cal.tests;
      std::printf("%s: %s: predicting %s at the calibrated parameters: %zu pressures x %d specimens\n",
                  folder.c_str(), material.c_str(), walls ? "the walled cell" : predict_template->path.c_str(),
                  tests.size(), specimens);
      std::vector<Prediction> p = walls ? predict_walls(*walls, cal.model, tests, specimens, jobs)
                                        : predict_at(base, cal.model, tests);
      for (std::size_t k = 0; k < p.size() && k < cal.sim.size(); ++k) p[k].periodic_q_peak = cal.sim[k].q_peak;
      for (Prediction& x : p) {
        curves.insert(curves.end(), x.members.begin(), x.members.end());
        all.push_back(std::move(x));
      }
    }
    const std::string md = prediction_markdown(all, data.q_measure);
    io::write_text_atomic(folder + "/prediction.csv", prediction_csv(all, data.q_measure));
    write_measured_curves(folder + "/prediction_curves.csv", curves, test + " at the calibrated parameters",
                          name_of(data.q_measure));
    std::printf("\nprediction (%s at the calibrated parameters):\n%s", test.c_str(), md.c_str());
    run_plot_script("plot_prediction.py", {folder});
    return prediction_section(test, specimens, data.q_measure, md, discrepancy);
  }
  /// The errors table, the curves in the measured-data format and the figure.
  void finish(const std::vector<MeasuredTest>& meas, const std::vector<MeasuredTest>& sim,
              const std::string& what) const {
    io::write_text_atomic(folder + "/errors.csv", errors_csv(meas, sim));
    write_measured_curves(folder + "/simulated_curves.csv", sim, "simulated by " + what);
    if (data.curves) write_measured_curves(folder + "/measured_curves.csv", meas, "measured: " + data.path);
    run_plot_script("plot_calibration.py", {folder});
  }
};

/// The extension a diagnosis reports against the base: the one its verdict names first, else the best by BIC
/// (a candidate, to show what it would change).
const ExtensionFit* top_fit(const Diagnosis& dg) {
  const ExtensionFit* top = nullptr;
  for (const ExtensionFit& f : dg.fits)
    if (dg.verdict.rfind(f.ext.name, 0) == 0) return &f;
  for (const ExtensionFit& f : dg.fits)
    if (!top || f.bic < top->bic) top = &f;
  return top;
}

}  // namespace

int calibrate_job(const Config& base, const CalibrationOptions& o) {
  Session ss(base, o, "calibrate");
  std::ostringstream table;
  table << "material,parameter,value,low95,high95,reference,chi2,data,runs\n";
  std::vector<MeasuredTest> all_meas, all_sim;
  std::map<std::string, Calibrated> models;
  for (const auto& by : by_material(ss.data, o.material)) {
    // Named, not structured, bindings: a lambda below captures them (C++17 cannot capture a structured binding).
    const std::string& material = by.first;
    const std::vector<MeasuredTest>& tests = by.second;
    std::printf("calibrate: %s, %zu tests, free %zu parameters, %zu balls in %s\n", material.c_str(), tests.size(),
                ss.free.size(), ss.lab.balls(), ss.cell_text().c_str());
    const long runs0 = ss.lab.runs();
    const Misfit misfit = ss.misfit_of(base, material, tests);  // sets the ensemble ("auto": from the scatter)
    auto fit = [&](const Misfit& m, const std::string& what) {
      const long start = ss.lab.runs();
      const long planned = planned_points(static_cast<int>(ss.free.size())) * static_cast<long>(tests.size()) *
                           ss.lab.members();
      Progress progress(what + " " + material, planned);
      CalibrationResult r = calibrate(ss.lab, model_of(base), ss.free, tests, m, 4, [&](long done, long, Real chi2) {
        char extra[64];
        std::snprintf(extra, sizeof extra, "runs, best chi2 %.1f", chi2);
        progress.update(done - start, extra);
      });
      progress.finish("");
      return r;
    };
    CalibrationResult r = fit(misfit, "calibrate");
    if (ss.two_fidelity) {
      // The boundary's discrepancy at the periodic optimum, then the cell calibrated to the data less it.
      std::printf("calibrate: %s: two fidelities: the membrane test and every periodic specimen at the periodic "
                  "optimum\n", material.c_str());
      const std::vector<Prediction> mem = ss.predict_at(base, r.model, tests);
      const Discrepancy d = measure_discrepancy(misfit, mem, ss.lab.run_ensemble(r.model, tests, true));
      const std::string text = discrepancy_text(misfit, d, tests);
      std::printf("%s", text.c_str());
      ss.discrepancy += text;
      Misfit corrected = misfit;
      corrected.add_discrepancy(d.delta, d.sd, "two fidelities: the data less the membrane test's excess over the "
                                               "periodic cell at the periodic optimum (" + ss.predict_template->path +
                                               "), with its standard error");
      r = fit(corrected, "calibrate (corrected)");
    }
    for (std::size_t k = 0; k < ss.free.size(); ++k) {
      const FreeParam& f = ss.free[k];
      const Real ref = ss.reference(material, f.name);
      std::printf("calibrate: %s: %s = %.4g%s\n", material.c_str(), f.name.c_str(), f.shown * r.values[k],
                  std::isfinite(ref) ? fmt(" (reference %g)", ref).c_str() : "");
      table << material << "," << f.name << "," << fmt("%.6g", f.shown * r.values[k]) << ","
            << fmt("%.6g", f.shown * r.interval[k].first) << "," << fmt("%.6g", f.shown * r.interval[k].second) << ","
            << (std::isfinite(ref) ? fmt("%g", ref) : "") << "," << fmt("%.3f", r.best.chi2) << "," << r.data << "," << ss.lab.runs() - runs0 << "\n";
    }
    std::printf("%s", uncertainty_text(r, material, "calibrate").c_str());
    for (const std::string& note : r.widened) std::printf("calibrate: %s: %s\n", material.c_str(), note.c_str());
    for (const std::string& name : r.at_edge())
      std::printf("calibrate: %s: WARNING: %s is at the edge of its range: widen it (the optimum may lie "
                  "outside)\n", material.c_str(), name.c_str());
    std::printf("calibrate: %s: chi2 %.1f on %d data after %ld runs\n", material.c_str(), r.best.chi2, r.data,
                ss.lab.runs() - runs0);
    all_meas.insert(all_meas.end(), tests.begin(), tests.end());
    all_sim.insert(all_sim.end(), r.best.sim.begin(), r.best.sim.end());
    models[material] = Calibrated{tests, r.model, r.best.sim};
  }
  if (ss.two_fidelity)
    std::printf("calibrate: two fidelities: the table sets the periodic cell against the data as measured; it was "
                "fitted to them less the boundary's discrepancy, and the membrane prediction below is the test "
                "that compares with the lab\n");
  print_errors(all_meas, all_sim);
  io::write_text_atomic(ss.folder + "/calibrated.csv", table.str());
  std::printf("calibrate: %s in %s; results in %s (calibrated.csv, errors.csv, simulated_curves.csv)\n",
              ss.runs_text().c_str(), format_duration(ss.lab.seconds()).c_str(), ss.folder.c_str());
  ss.finish(all_meas, all_sim, "the calibrated parameters");
  const std::string prediction = ss.predict_boundary(base, models);
  if (!prediction.empty()) io::write_text_atomic(ss.folder + "/prediction.md", prediction);
  return 0;
}

int diagnose_job(const Config& base, const CalibrationOptions& o) {
  Session ss(base, o, "diagnose");
  if (ss.two_fidelity)
    std::printf("diagnose: note: the diagnosis fits the periodic cell; two fidelities apply to calibrate (the "
                "membrane prediction at the end shows what the boundary adds)\n");
  std::ostringstream md, csv;
  md << "# Diagnosis of " << o.data << "\n\n"
     << "Simulator: the cell triaxial test in " << ss.cell_text() << ", an ensemble of " << ss.lab.members()
     << " specimens of " << ss.lab.balls() << " balls (packing seeds from " << base.run.seed
     << "), each prepared once; every parameter point runs them all and compares their mean. Free base parameters:";
  for (const FreeParam& f : ss.free) md << " " << f.name;
  md << ". Misfit: chi2 over " << (ss.data.curves ? "q and eps_v at fixed axial strains (0.02% to 15%)"
                                                  : "the summary quantities given")
     << ", with the data's noise, the measured specimen's own scatter and the simulator's standard error "
        "(host/fit/misfit.hpp); noise: " << (ss.noise.mode == "lab" ? ss.noise.lab_name : "the data's") << ".\n\n";
  if (!ss.ref.values.empty())
    md << "Reference values: " << ss.ref.path << (ss.ref.comment.empty() ? "" : ": " + ss.ref.comment)
       << " The calibrated values belong to this simulator (its cell, density and boundary), the reference values to "
          "the model they were calibrated with: a difference between them measures the two simulators as much as "
          "the data.\n\n";
  for (const std::string& n : ss.data.notes) md << "Note on the data: " << n << "\n\n";
  csv << "material,model,parameter,value,chi2,bic,heldout_chi2,runs\n";
  std::vector<MeasuredTest> all_meas, all_sim, all_ext;
  std::map<std::string, Calibrated> models;
  for (const auto& [material, tests] : by_material(ss.data, o.material)) {
    std::printf("diagnose: %s, %zu tests, %zu balls in %s\n", material.c_str(), tests.size(), ss.lab.balls(),
                ss.cell_text().c_str());
    const Misfit misfit = ss.misfit_of(base, material, tests);
    const Diagnosis dg = diagnose(ss.lab, model_of(base), ss.free, tests, misfit, true);
    std::printf("diagnose: %s: verdict: %s\n  %s\n", material.c_str(), dg.verdict.c_str(), dg.explanation.c_str());
    std::printf("%s", uncertainty_text(dg.base, material, "diagnose").c_str());
    std::string edge, widened;
    for (const std::string& note : dg.base.widened) {
      std::printf("diagnose: %s: %s\n", material.c_str(), note.c_str());
      widened += (widened.empty() ? "" : "; ") + note;
    }
    for (const std::string& name : dg.base.at_edge()) edge += (edge.empty() ? "" : ", ") + name;
    if (!edge.empty())
      std::printf("diagnose: %s: WARNING: %s at the edge of the search range\n", material.c_str(), edge.c_str());
    md << "## " << material << "\n\n**Verdict: " << dg.verdict << ".** " << dg.explanation << "\n\n"
       << noise_table(misfit, tests)
       << (widened.empty() ? "" : "Search ranges: " + widened + ".\n\n")
       << (edge.empty() ? "" : "**Warning:** the base model's " + edge + " lies at the edge of its search range: the "
                               "optimum may lie outside, and part of the misfit may be the range's, not the model's.\n\n")
       << "| model | parameters | chi2 | BIC | held-out chi2 | runs |\n|---|---|---|---|---|---|\n| base | ";
    for (std::size_t k = 0; k < ss.free.size(); ++k) {
      md << ss.free[k].name << " = " << fmt("%.4g", ss.free[k].shown * dg.base.values[k]) << " ";
      csv << material << ",base," << ss.free[k].name << "," << fmt("%.6g", ss.free[k].shown * dg.base.values[k]) << ","
          << fmt("%.3f", dg.base.best.chi2) << "," << fmt("%.3f", dg.base_bic) << "," << fmt("%.3f", dg.base_heldout)
          << "," << dg.base.design.size() * tests.size() << "\n";
    }
    md << "| " << fmt("%.1f", dg.base.best.chi2) << " | " << fmt("%.1f", dg.base_bic) << " | "
       << fmt("%.1f", dg.base_heldout) << " | " << dg.base.design.size() * tests.size() * ss.lab.members() << " |\n";
    for (const ExtensionFit& f : dg.fits) {
      md << "| " << f.ext.name << " | ";
      for (std::size_t k = 0; k < ss.free.size(); ++k)
        md << ss.free[k].name << " = " << fmt("%.4g", ss.free[k].shown * f.values[k]) << " ";
      const Real shown = free_param(f.ext.param).shown;
      md << f.ext.param << " = " << fmt("%.3g", shown * f.strength) << " | " << fmt("%.1f", f.best.chi2) << " | "
         << fmt("%.1f", f.bic) << " | " << fmt("%.1f", f.heldout) << " | " << f.runs << " |\n";
      csv << material << "," << f.ext.name << "," << f.ext.param << "," << fmt("%.6g", shown * f.strength) << ","
          << fmt("%.3f", f.best.chi2) << "," << fmt("%.3f", f.bic) << "," << fmt("%.3f", f.heldout) << "," << f.runs
          << "\n";
    }
    if (!ss.ref.values.empty()) {
      const ExtensionFit* named = nullptr;  // the extension the verdict names first, if any
      for (const ExtensionFit& f : dg.fits)
        if (dg.verdict.rfind(f.ext.name, 0) == 0) named = &f;
      md << "\nCalibrated values beside the reference (" << ss.ref.path << "):\n\n| parameter | base model | "
         << (named ? "base + " + named->ext.name + " | " : "") << "reference |\n|---|---|" << (named ? "---|" : "")
         << "---|\n";
      for (std::size_t k = 0; k < ss.free.size(); ++k) {
        const Real ref = ss.reference(material, ss.free[k].name);
        md << "| " << ss.free[k].name << " | " << fmt("%.4g", ss.free[k].shown * dg.base.values[k]) << " | "
           << (named ? fmt("%.4g", ss.free[k].shown * named->values[k]) + " | " : "")
           << (std::isfinite(ref) ? fmt("%g", ref) : std::string("-")) << " |\n";
      }
    }
    md << "\nEach extension against the base model:\n\n";
    for (const ExtensionFit& f : dg.fits) md << "- **" << f.ext.name << "**: " << f.reason << "\n";
    for (const std::string& n : dg.notes) md << "- " << n << "\n";
    md << "\nThe base model's calibrated values:\n\n```\n" << uncertainty_text(dg.base, material, "diagnose")
       << "```\n";
    md << "\n" << ss.state_text(misfit, tests);
    const ExtensionFit* top = top_fit(dg);
    if (top) {
      md << gain_tables(misfit, tests, dg.base.best, top->best,
                        top->ext.name + (dg.verdict == "none" ? " (candidate, not named)" : ""));
      all_ext.insert(all_ext.end(), top->best.sim.begin(), top->best.sim.end());
      std::printf("diagnose: %s: gain of %s: chi2 %.1f -> %.1f, held-out chi2 %.1f -> %.1f (diagnosis.md has it by "
                  "pressure, strain range and quantity)\n", material.c_str(), top->ext.name.c_str(),
                  dg.base.best.chi2, top->best.chi2, dg.base_heldout, top->heldout);
    }
    md << "\n";
    all_meas.insert(all_meas.end(), tests.begin(), tests.end());
    all_sim.insert(all_sim.end(), dg.base.best.sim.begin(), dg.base.best.sim.end());
    models[material] = Calibrated{tests, dg.base.model, dg.base.best.sim};
  }
  if (ss.lab.failed_runs() > 0) md << "**Warning:** " << ss.failed_text() << ".\n\n";
  md << "![measured and simulated: the base model in full lines, the extended one dashed](calibration.png)\n";
  if (all_ext.size() == all_meas.size())
    write_measured_curves(ss.folder + "/extended_curves.csv", all_ext, "simulated by the extended model of each material");
  io::write_text_atomic(ss.folder + "/diagnosis.md", md.str());
  io::write_text_atomic(ss.folder + "/models.csv", csv.str());
  std::printf("diagnose: %s in %s; report in %s/diagnosis.md\n", ss.runs_text().c_str(),
              format_duration(ss.lab.seconds()).c_str(), ss.folder.c_str());
  ss.finish(all_meas, all_sim, "the calibrated base model");
  // The report stands before the membrane tests run; their section is added when they end.
  const std::string prediction = ss.predict_boundary(base, models);
  if (!prediction.empty()) io::write_text_atomic(ss.folder + "/diagnosis.md", md.str() + "\n" + prediction);
  return 0;
}

}  // namespace dem
