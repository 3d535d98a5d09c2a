#pragma once
/// What a calibration or a diagnosis will run, stage by stage, and about how long it takes on this machine, told
/// before the first packing (calibrate and diagnose print it; --plan prints it and stops). Counts follow the stages
/// as host/study/calibration_jobs.cpp runs them; times are the particle-steps of host/lab/run_cost.hpp at the speed
/// its probe measures here. Where a choice made on the way decides the size of a stage (an "auto" ensemble), the
/// stage gives its range.
#include <map>
#include <string>
#include <vector>

#include "host/config/config.hpp"
#include "host/data/compression_data.hpp"
#include "host/data/measured.hpp"

namespace dem {

/// A job whose plan's upper time is above this many seconds asks for --yes (or a smaller setting) before it starts.
constexpr double kPlanBoundSeconds = 4 * 3600;
/// A plan above this is refused even with --yes (a job planned at 1,454 hours once started on --yes alone): a week.
constexpr double kPlanCeilingSeconds = 7 * 24 * 3600;

struct PlanStage {
  std::string name;           ///< "scatter runs"
  std::string work;           ///< what runs: "48 runs of 120 balls (16 specimens x 3 tests)"
  std::string setting;        ///< the key or option that sizes it most ("[calibrate] scatter_specimens")
  double particle_steps = 0;  ///< at the upper end of the range
  double low = 0, high = 0;   ///< wall seconds on this machine (equal where nothing on the way decides)
};

struct JobPlan {
  std::vector<PlanStage> stages;
  std::vector<std::string> notes;  ///< the choices behind the counts, the speed measured
  double low() const;
  double high() const;
  double particle_steps() const;
  /// The stage of the largest upper time (the one a smaller setting helps most).
  const PlanStage& costliest() const;
  /// The plan as printed: one line a stage, the totals, then the notes; each line starts with `kind`.
  std::string text(const std::string& kind) const;
};

/// What the plan needs to know of a job.
struct PlanInput {
  Config cell;  ///< the reference test's cell as the config gives it ([calibrate] cell_factor not yet applied), its store set
  std::map<std::string, std::vector<TriaxialTest>> materials;  ///< the data's tests by material
  std::vector<TriaxialTest> state_tests;  ///< the tests whose void ratio the lab's specimens are matched to (all)
  std::vector<std::string> free;     ///< the free parameters
  bool diagnose = false;
  bool two_fidelity = false;
  const Config* membrane = nullptr;  ///< the membrane test that predicts (and corrects two fidelities), or none
  bool walls = false;                ///< the prediction is the cell between six walls
  int at_once = 1;                   ///< simulator runs at once
  std::vector<TriaxialTest> held_out;  ///< tests left out of the fit and predicted (--hold-out)
  std::vector<std::string> reference_runs;  ///< materials whose reference point (--reference) is run after the fit
  std::vector<CompressionTest> compression;  ///< --compression's tests, fitted with their material's triaxial tests
};

/// The plan of a job; measures the engine's speed on the cells it will run (about a second).
JobPlan plan_job(const PlanInput& in);

}  // namespace dem
