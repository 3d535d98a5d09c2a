#pragma once
/// What `calibrate` and `diagnose` share (host/study/calibration_jobs.cpp): the data, the free parameters, the
/// reference test's simulator, the noise, the prediction that ends them, and a new result folder.
#include <chrono>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <system_error>
#include <vector>

#include "host/study/calibration_jobs.hpp"
#include "host/data/compression_data.hpp"
#include "host/fit/calibrate.hpp"
#include "host/fit/job_plan.hpp"
#include "host/fit/misfit.hpp"
#include "host/fit/prediction.hpp"
#include "host/lab/periodic_lab.hpp"

namespace dem {

/// The data's tests by material: all of them, or those of `only` (DataError naming the file where it has none).
std::map<std::string, std::vector<TriaxialTest>> by_material(const MeasuredData& d, const std::string& only);

/// How far beyond the data's last strain the cell shears (a tenth: the misfit's last feature lies inside the cell's
/// curve, with records on both sides for its window).
constexpr Real kStrainBeyondData = 1.1;
/// `cell` sheared no further than curve data need: to kStrainBeyondData times their last axial strain where the config
/// asks for more (the shear's records up to there are the same bit for bit, and the misfit compares no strain beyond
/// the data's). Summary data (a peak, an end value) keep the config's strain.
Config sheared_for(Config cell, const MeasuredData& data);
/// The reference test's cell (JobInputs::cell), sheared as far as the data need, its packings kept in (and read from)
/// the output folder's .specimens/cells, where a later job on the same base finds them.
Config stored_cell(const Config& cell, const CalibrationOptions& o, const MeasuredData& data);

/// A material's calibration as the prediction needs it: its tests, the model, and the periodic cell's tests at it.
struct Calibrated {
  std::vector<TriaxialTest> tests;
  Model model;
  std::vector<TriaxialTest> sim;  ///< in the order of tests
  std::vector<TriaxialTest> held_out;  ///< tests left out of the fit (--hold-out), predicted after the fitted ones
};

/// Removes a result folder that is still empty when the job ends: a refusal after the folder was made.
struct EmptyFolderRemover {
  std::string path;
  EmptyFolderRemover(const EmptyFolderRemover&) = delete;
  EmptyFolderRemover& operator=(const EmptyFolderRemover&) = delete;
  ~EmptyFolderRemover() {
    std::error_code ec;
    namespace fs = std::filesystem;
    if (fs::is_directory(path, ec) && fs::is_empty(path, ec)) fs::remove(path, ec);
  }
};

/// What a calibrate or diagnose job is asked to do, read and checked before any work: the data, the free
/// parameters, the noise, the prediction; and the plan of the work (--plan stops after it).
struct JobInputs {
  MeasuredData data;
  Config cell;  ///< the reference test's cell (reference_cell of --reference-test), read once for the whole job
  ReferenceValues ref;
  std::vector<FreeParam> free;
  NoiseOptions noise;
  std::optional<Config> predict_template;
  bool walls_prediction = false;  ///< the prediction is the reference cell between six walls (kPredictWalls)
  int workers = 1;
  bool two_fidelity = false;  ///< the reference test: the periodic cell corrected by the membrane test
  QMeasure cell_q = QMeasure::kAreaCorrected;  ///< the q the reference cell's tests carry (reference_q_measure)
  std::vector<TriaxialTest> held_out;  ///< the tests --hold-out took out of `data` (the fit never sees them)
  std::vector<CompressionTest> compression;  ///< --compression's tests, each of a material of `data`
  /// The compression tests of `material`.
  std::vector<CompressionTest> compression_of(const std::string& material) const;
  /// `kind`: the job ("calibrate" or "diagnose"), whose search decides what --compression may go with.
  JobInputs(const Config& base, const CalibrationOptions& o, const std::string& kind);
  /// The job's plan (host/fit/job_plan.hpp), printed. A plan above kPlanBoundSeconds without --yes is refused
  /// (ConfigError naming its costliest stage and the setting that sizes it).
  JobPlan announce_plan(const Config& base, const CalibrationOptions& o, const std::string& kind) const;
  /// The reference's value of each free parameter for `material` (in the keys' units; NaN where it gives none).
  std::vector<Real> reference_point(const std::string& material) const;
  /// Whether calibrate runs the reference point of `material` after its fit: the reference gives every free parameter
  /// and the fit's misfit is the data's (two fidelities fit a corrected one).
  bool runs_reference(const std::string& material) const;
};

/// What the job's data are taken to be (host/study/data_scope.cpp). take_walled_size: between walls the specimen's size
/// is part of the test, so tests without specimen_balls take the walled cell's balls (with a note), and a walled cell
/// smaller than the data's specimen is said. hold_out: the tests at --hold-out's pressure out of `data`, returned;
/// DataError where no test has it or a material the job calibrates would keep none. check_enough_data: DataError where
/// a material's summary values are fewer than the free parameters (a ridge of fits, each with chi2 0).
void take_walled_size(const Config& cell, MeasuredData& data);
std::vector<TriaxialTest> hold_out(const CalibrationOptions& o, MeasuredData& data);
void check_enough_data(const CalibrationOptions& o, const MeasuredData& data, std::size_t free);
/// DataError where a test's specimen_balls lie below the simulator cell's balls: the cell's bias check extrapolates
/// toward larger specimens only (a 10-ball specimen against a 120-ball cell was extrapolated to q -45%).
void check_specimen_sizes(const Config& base, const Config& cell, const MeasuredData& data);
/// The inputs that decide a job's runs (the data's bytes, the config's keys, the options), in the result folder's
/// job_inputs.txt; a --resume with other inputs is refused before any work, naming what differs.
void record_job_inputs(const Config& base, const CalibrationOptions& o, const std::string& folder);
void check_resumed_inputs(const Config& base, const CalibrationOptions& o, const std::string& kind);

/// Where a job writes and what it says at its end: a new result folder (or the one resumed), its plan beside the time
/// taken, how the runs used the workers, and the two fidelities' account for the prediction's section.
struct JobReport {
  std::chrono::steady_clock::time_point started = std::chrono::steady_clock::now();
  JobPlan plan;
  std::string folder, output;
  EmptyFolderRemover remover{folder};
  std::string discrepancy;  ///< what the two fidelities measured, for the report
  JobReport(JobPlan announced, const CalibrationOptions& o, const std::string& kind);
  /// The plan's estimate beside the job's time so far, for the job's last lines.
  std::string plan_text() const;
  /// How the runs used the workers: their mean length, the workers' busy share while the pools ran (the rest
  /// they waited for a batch's longest run) and the pools' share of the job's time (the rest the fits took).
  std::string workers_text() const;
  /// pools.csv in the result folder: each pool's pieces and their run times, and the job's wall time so far
  /// (tools/schedule_projection.py projects the job on more ranks from it).
  void write_pools() const;
  /// The errors table, the curves in the measured-data format and the figure.
  void finish(const MeasuredData& data, const std::vector<TriaxialTest>& meas, const std::vector<TriaxialTest>& sim,
              const std::string& what) const;
};

/// What calibrate and diagnose share: the job's inputs, read and checked before any work and not changed after; its
/// report; and its lab, the simulator of the reference test on specimens matched to the data's state, with what the
/// lab measures once for the job (the state, the scatter, the membrane runs).
struct Session {
  const JobInputs in;
  JobReport report;
  StateMatch state;  ///< the data's void ratio and the preparation that packs it, on the lab's present cell
  PeriodicLab lab;
  Session(const Config& base, const CalibrationOptions& o, const std::string& kind);
  /// The reference test's cell, for the report.
  std::string cell_text() const;
  /// "N runs" and how many of them a resumed session read from its store.
  std::string runs_text() const;
  /// How many runs a blow-up stopped, at up to which pressure, and the fix: their data count as missing
  /// (kMissingResidual), which pushes the fit away from where they happen.
  std::string failed_text() const;
  std::vector<std::string> free_names() const;
  /// The membrane test at `model` on every test of `tests`, q in the data's measure (a template must be set).
  /// Each (point, test) runs once per job: a membrane run the two fidelities made is the prediction's where the
  /// answer lies at a point they ran (membrane_runs_).
  std::vector<Prediction> predict_at(const Config& base, const Model& model,
                                     const std::vector<TriaxialTest>& tests) const;
  /// The misfit of a material's tests: the ensemble run at the base model, its scatter beside the data's noise.
  Misfit misfit_of(const Config& base, const std::string& material, const std::vector<TriaxialTest>& tests);
  /// The reference value of a parameter for a material, in the key's unit; NaN when there is none.
  Real reference(const std::string& material, const std::string& name) const;
  /// The test with a boundary at each material's calibrated model (`models`, by material), beside the data: the
  /// membrane test of the template or the walled cell. Writes prediction.csv, prediction_curves.csv and
  /// prediction.png, prints the table, and returns it as Markdown ("" when there is no prediction).
  std::string predict_boundary(const Config& base, const std::map<std::string, Calibrated>& models) const;

 private:
  /// The membrane runs made, by the free parameters' values and the test (material, sigma3).
  mutable std::map<std::string, Prediction> membrane_runs_;
  Config matched(const Config& base, int workers);
};

/// The misfit with the simulator's scatter measured at the calibrated point r.model too (the scatter specimens run
/// there; each datum takes the larger), and r whitened again by it; the change of the simulator's scatter is said. One
/// specimen a point: those runs join the design at the answer, and the misfit counts the ensemble the surfaces are worth.
Misfit rescattered(Session& ss, const std::string& material, const std::vector<TriaxialTest>& tests,
                   const Misfit& misfit, CalibrationResult& r, const Model& base);
/// Where the reference gives every free parameter: its rise over the joint 95% region of r, and its chi2 run on the
/// ensemble against `misfit` where the job runs it (runs_reference); NaN where not, and the line said.
std::pair<Real, Real> place_reference(Session& ss, const std::string& material, const std::vector<TriaxialTest>& tests,
                                      const Misfit& misfit, const CalibrationResult& r);

}  // namespace dem
