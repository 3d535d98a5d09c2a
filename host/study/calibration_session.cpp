#include "host/study/calibration_session.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "host/fit/calibration_report.hpp"
#include "host/fit/diagnose.hpp"
#include "host/fit/two_fidelity.hpp"
#include "host/io/io_hdf5.hpp"
#include "host/triax/summary.hpp"
#include "host/util/process_pool.hpp"
#include "host/util/ranks.hpp"
#include "host/util/progress.hpp"
#include "host/util/text_format.hpp"

namespace dem {

namespace fs = std::filesystem;

std::string JobReport::plan_text() const {
  return "the plan said about " +
         (plan.high() - plan.low() < 0.5 ? format_duration(plan.high())
                                         : format_duration(plan.low()) + " to " + format_duration(plan.high())) +
         "; the job took " + format_duration(seconds_since(started));
}

JobReport::JobReport(JobPlan announced, const CalibrationOptions& o, const std::string& kind)
    : plan(std::move(announced)),
      folder(o.resume.empty() ? new_dated_folder(o.output, kind) : resumed_folder(o.resume, kind)),
      output(o.resume.empty() ? o.output : resumed_parent(o.resume)) {}

Session::Session(const Config& base, const CalibrationOptions& o, const std::string& kind)
    : in(base, o, kind), report(in.announce_plan(base, o, kind), o, kind),
      lab(matched(stored_cell(in.cell, o, in.data), o.workers), true, o.workers) {
  const std::string& folder = report.folder;
  ranks::check_shared_folder(folder);  // every rank reads the run store there
  lab.set_run_store(folder + "/runs");
  set_stop_note("the runs so far are kept in " + folder + "/runs: the same command with --resume " + folder +
                " continues");
  lab.set_q_measure(in.cell_q);
  if (!o.resume.empty())
    std::printf("%s: resuming in %s: the runs stored there are read, not run again%s\n", kind.c_str(), folder.c_str(),
                fs::exists(folder + "/job_inputs.txt") ? " (same data, config and options)"
                                                       : "; the folder holds no record of its inputs, so they are not "
                                                         "checked against this job's");
  record_job_inputs(base, o, folder);
  if (lab.config().periodic.boundary == CellBoundary::walls) {
    const bool fixed = in.cell_q == QMeasure::kFixedArea;
    std::printf("%s: note: the walled cell compares its q over the %s cross-section (%s%s); its walls also give q "
                "over the %s one (%s)\n", kind.c_str(), fixed ? "initial" : "current", name_of(in.cell_q),
                in.data.q_measure_given ? ", the data's q_measure"
                                     : ", taken where the data say no q_measure: name yours in a q_measure column",
                fixed ? "current" : "initial", name_of(fixed ? QMeasure::kAreaCorrected : QMeasure::kFixedArea));
  }
  if (const Real end = lab.config().periodic.triax.target_strain; end < base.periodic.triax.target_strain)
    std::printf("%s: note: the cell shears to %.3g%% axial strain, a tenth beyond the data's last, not to the "
                "config's %.3g%% ([periodic] target_axial_strain_pct): the data compare nothing beyond\n", kind.c_str(),
                100 * end, 100 * base.periodic.triax.target_strain);
}

std::string Session::cell_text() const {
  return lab.config().periodic.boundary == CellBoundary::walls
             ? "the cell between six walls (stresses measured at the walls, as a walled test measures them)"
             : "the periodic cell (stresses from its contacts: the specimen's interior, without a boundary)";
}

std::string Session::runs_text() const {
  const long read = lab.stored_runs_read();
  return std::to_string(lab.runs()) + " runs" +
         (read > 0 ? " (" + std::to_string(read) + " of them read from the run store)" : "");
}

std::string JobReport::workers_text() const {
  const PoolUse use = pool_use();
  const double job = seconds_since(started);
  const LabTime t = lab_time();
  std::string s = "the job's " + format_duration(job) + fmt(": %.0f simulator runs ", static_cast<double>(t.ran)) +
                  format_duration(t.runs) + (t.ran > 0 ? fmt(" (%.1f s a run)", t.runs / t.ran) : std::string()) +
                  ", packing specimens " + format_duration(t.packing) + ", the rest (fits, reports) " +
                  format_duration(std::max(0.0, job - t.runs - t.packing));
  if (use.pieces == 0) return s + "; one run at a time";
  return s + fmt("; %.0f pieces of work in child processes", static_cast<double>(use.pieces)) +
         fmt(", %.1f s each on average", use.busy / use.pieces) +
         fmt(", the workers busy %.0f%% of the time the pools ran", 100 * use.busy / std::max(use.offered, 1e-9)) +
         fmt(" (idle %.0f worker-seconds, waiting for the longest piece of a batch)", use.idle());
}

void JobReport::write_pools() const { io::write_text_atomic(folder + "/pools.csv", pools_csv(seconds_since(started))); }

std::string Session::failed_text() const {
  return std::to_string(lab.failed_runs()) + " of the runs stopped at a blow-up" +
         fmt(" (up to %g kPa)", 1e-3 * lab.highest_failed_sigma3()) +
         ", their data counted as missing: where the overlaps are the contacts' physics (soft contacts at high "
         "pressure), raise [solver] overlap_limit (docs/config.md)";
}

std::vector<std::string> Session::free_names() const {
  std::vector<std::string> names;
  for (const FreeParam& f : in.free) names.push_back(f.name);
  return names;
}

std::vector<Prediction> Session::predict_at(const Config& base, const Model& model, const std::vector<TriaxialTest>& tests) const {
  std::string at;
  for (const std::string& name : free_names()) at += fmt("%.17g,", get_param(model, name));
  auto key = [&](const TriaxialTest& t) { return at + t.material + fmt(",%.17g", t.sigma3); };
  std::vector<TriaxialTest> missing;
  for (const TriaxialTest& t : tests)
    if (!membrane_runs_.count(key(t))) missing.push_back(t);
  if (missing.size() < tests.size())
    std::printf("prediction: %zu of %zu membrane tests at this point were run before in this job: taken, not run "
                "again\n", tests.size() - missing.size(), tests.size());
  if (!missing.empty()) {
    const std::vector<Prediction> ran = predict(*in.predict_template, model, free_names(), missing, in.data.q_measure,
                                                static_cast<int>(base.calibrate.predict_specimens),
                                                report.output + "/.specimens", true, in.workers);
    for (std::size_t k = 0; k < ran.size(); ++k) membrane_runs_[key(missing[k])] = ran[k];
  }
  std::vector<Prediction> out;
  for (const TriaxialTest& t : tests) out.push_back(membrane_runs_.at(key(t)));
  return out;
}

Config Session::matched(const Config& base, int workers) {
  return matched_state(base, in.data.tests, state, true, match_plan(base, workers));
}

Misfit Session::misfit_of(const Config& base, const std::string& material, const std::vector<TriaxialTest>& tests) {
  std::printf("%s: %s: measuring the simulator's scatter: %d specimens of %zu balls at the base model\n",
              report.folder.c_str(), material.c_str(), lab.specimens(), lab.balls());
  lab.set_progress("  " + material + ": scatter");
  const NoiseBudget budget = decide_noise_budget(lab, model_of(base), tests, in.noise, true, state);
  lab.set_progress("");
  state = budget.state;  // a grown cell was matched again: the next material's budget starts from it
  const Misfit m(tests, in.noise, budget);
  if (!m.cell_bias_finding().empty())
    std::printf("%s: %s: FINDING: %s\n", report.folder.c_str(), material.c_str(), m.cell_bias_finding().c_str());
  for (const std::string& n : m.notes()) std::printf("  noise: %s\n", n.c_str());
  const Real ratio = m.ensemble_ratio();
  const bool one_specimen = base.calibrate.one_specimen();
  const bool chosen = base.calibrate.ensemble == kAutoEnsemble && !one_specimen;
  // An "auto" cell grows only with an "auto" ensemble: a fixed ensemble fixes the cost per point.
  const bool cell_chosen = chosen && base.calibrate.cell_factor == kAutoCell;
  std::printf("  cell: %zu balls, %d x the config's (%s)%s\n", lab.balls(), lab.cell_factor(),
              base.calibrate.cell_factor != kAutoCell ? "[calibrate] cell_factor" : cell_chosen ? "chosen" : "kept",
              lab.cell_factor() > 1 && cell_chosen ? ": all the scatter specimens of the config's cell fell short"
                                                   : "");
  if (one_specimen) {
    std::printf("  ensemble: one specimen a point ([calibrate] method); the surfaces average the points' scatter, and "
                "the answer's is measured on the %d scatter specimens\n", lab.specimens());
    return m;
  }
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

Real Session::reference(const std::string& material, const std::string& name) const {
  auto m = in.ref.values.find(material);
  if (m == in.ref.values.end()) return std::nan("");
  auto v = m->second.find(name);
  return v == m->second.end() ? std::nan("") : v->second;
}

std::string Session::predict_boundary(const Config& base, const std::map<std::string, Calibrated>& models) const {
  if (!in.predict_template && !in.walls_prediction) {
    std::printf("%s: no prediction ([calibrate] predict or --predict names a membrane test, or walls)\n",
                report.folder.c_str());
    return "";
  }
  std::optional<Config> walls;
  if (in.walls_prediction) {
    StateMatch walls_state;  // the walled cell's own preparation to the data's state
    Config walled = reference_cell(base, kPredictWalls);
    walled.packing_store = lab.config().packing_store;
    walls = matched_state(walled, in.data.tests, walls_state, true, match_plan(walled, in.workers));
  }
  const std::string test = walls ? walled_cell_text(*walls) : membrane_test_text(*in.predict_template);
  const int specimens = static_cast<int>(base.calibrate.predict_specimens);
  std::vector<Prediction> all;
  std::vector<TriaxialTest> curves;
  for (const auto& [material, cal] : models) {
    std::vector<TriaxialTest> tests = cal.tests;
    tests.insert(tests.end(), cal.held_out.begin(), cal.held_out.end());
    std::printf("%s: %s: predicting %s at the calibrated parameters: %zu pressures x %d specimens\n",
                report.folder.c_str(), material.c_str(), walls ? "the walled cell" : in.predict_template->path.c_str(),
                tests.size(), specimens);
    std::vector<Prediction> p = walls ? predict_walls(*walls, cal.model, tests, specimens, in.workers)
                                      : predict_at(base, cal.model, tests);
    for (std::size_t k = 0; k < p.size() && k < cal.sim.size(); ++k) p[k].periodic_q_peak = cal.sim[k].q_peak;
    for (std::size_t k = cal.tests.size(); k < p.size(); ++k) p[k].held_out = true;
    for (Prediction& x : p) {
      curves.insert(curves.end(), x.members.begin(), x.members.end());
      all.push_back(std::move(x));
    }
  }
  const std::string md = prediction_markdown(all, in.data.q_measure);
  io::write_text_atomic(report.folder + "/prediction.csv", prediction_csv(all, in.data.q_measure));
  write_measured_curves(report.folder + "/prediction_curves.csv", curves, test + " at the calibrated parameters",
                        name_of(in.data.q_measure));
  std::printf("\nprediction (%s at the calibrated parameters):\n%s", test.c_str(), md.c_str());
  run_plot_script("plot_prediction.py", {report.folder});
  return prediction_section(test, specimens, in.data.q_measure, md, report.discrepancy);
}

void JobReport::finish(const MeasuredData& data, const std::vector<TriaxialTest>& meas,
                       const std::vector<TriaxialTest>& sim, const std::string& what) const {
  io::write_text_atomic(folder + "/errors.csv", errors_csv(meas, sim));
  write_measured_curves(folder + "/simulated_curves.csv", sim, "simulated by " + what);
  if (data.curves) write_measured_curves(folder + "/measured_curves.csv", meas, "measured: " + data.path);
  run_plot_script("plot_calibration.py", {folder});
}

}  // namespace dem
