#pragma once
/// The one time loop of every stage of a test: the run job, a specimen layer's compaction, the membrane test's
/// consolidation and shear, the periodic cell's consolidation and shear. A stage says what is its own: its control
/// before a step and whether the step measures, what it records after it, and when it is done. The loop does what
/// they share, in one order: the step, the checkpoint when due and the stop when asked, and on a blow-up the
/// stage's state saved for inspection before the error goes on.
#include <chrono>
#include <functional>
#include <string>
#include <vector>

#include "host/engine/checkpoint.hpp"
#include "host/engine/simulation.hpp"
#include "host/util/progress.hpp"
#include "host/util/sync_counts.hpp"

namespace dem {

/// Adds the wall seconds of its scope to a sum (a StageTiming's host parts).
class WallClock {
 public:
  explicit WallClock(double& sum) : sum_(sum), t0_(std::chrono::steady_clock::now()) {}
  ~WallClock() { sum_ += seconds_since(t0_); }
  WallClock(const WallClock&) = delete;
  WallClock& operator=(const WallClock&) = delete;

 private:
  double& sum_;
  std::chrono::steady_clock::time_point t0_;
};

/// What a stage does before a step: whether it is done before taking it (its end was seen in the state the last
/// step left), and whether the step measures the unbalanced force and kinetic energy (when the stage reads them).
struct StepPlan {
  bool done = false;
  bool measure = false;
};

struct StageSteps {
  long first = 1;  ///< the number of the stage's first step
  long last = 0;   ///< its cap: the stage takes no step beyond it
  /// Before step n: the stage's control (servo, boundary speeds), and what the step is to be.
  std::function<StepPlan(long n)> before;
  /// After step n, told whether it measured: records, snapshots, progress. True when the stage is done; then no
  /// checkpoint follows.
  std::function<bool(long n, bool measured)> after;
  /// Writes the stage's checkpoint after step n; unset: the stage keeps none.
  std::function<void(long n)> checkpoint;
  /// Saves the state a blow-up left, for inspection; unset: the error goes on as it is.
  std::function<void()> save_blowup;
};

/// What a stage's steps cost: wall-clock seconds in all, and the step's parts (StageTimes); the rest is the stage's
/// own host work between steps (servo, records, snapshots, progress, checkpoints).
struct StageTiming {
  std::string name;
  long balls = 0;
  long steps = 0;
  double wall = 0;
  StageTimes parts;
  /// Candidate pairs in the contact lists (touching or within the Verlet skin) per ball at the stage's end: what a
  /// ball-ball or ball-wall particle-step costs grows with them.
  double ball_pairs = 0, wall_pairs = 0;
  /// What the stage's steps made the host wait for, by part of the loop (sync_counts.hpp).
  SyncTally syncs{};
  /// Wall seconds of the host's work by where it is spent: the stage's control before a step (servo, boundary
  /// speeds), its work after one (records, micromechanics, snapshots, progress) and its checkpoints. On a GPU the
  /// host waits there for the steps launched before, so a part's time includes the device work it waits for.
  double control = 0, after = 0, checkpoints = 0;
  /// Per step, the step's and its control's (a servo's) counts: what every step pays, rebuilds and records left out.
  SyncCounts per_step_part() const {
    return syncs[static_cast<int>(SyncPart::kControl)] + syncs[static_cast<int>(SyncPart::kStep)];
  }
  double host() const { return wall - parts.loop(); }
  double rate() const { return wall > 0 ? static_cast<double>(balls) * static_cast<double>(steps) / wall : 0; }
};

/// The sampled parts of a stage's loop (forces, integration, boundaries, membrane, walls: timed one step in
/// kTimedEvery and scaled to the stage) are an estimate, and one stalled sample counts kTimedEvery times (a Hertz
/// consolidation on a busy machine read a host time of -63 ns a particle-step). The host's work and the rebuilds are
/// timed whole: the sampled parts are scaled down, in proportion, to the wall time those leave, so that host() is
/// never below the host's measured work.
void fit_sampled_parts(StageTiming& timing);

/// How a stage ended: the number of its last step, whether it was done (else it reached its cap), and its cost.
struct StageEnd {
  long step = 0;
  bool done = false;
  StageTiming timing;
};

/// Stage timings as CSV (timings.csv): per stage its balls, steps, wall seconds, particle-steps per second and
/// nanoseconds per particle-step in each part of the step and in the host's work between steps.
std::string timings_csv(const std::vector<StageTiming>& stages);
/// The same as a table for the log, one line a stage.
std::string timings_table(const std::vector<StageTiming>& stages);

/// Runs the stage's steps. `plan` (may be null) decides when a checkpoint is due, by the simulation's step count,
/// and when the job stops after one (RunStopped thrown).
StageEnd run_stage(Simulation& sim, const StageSteps& stage, CheckpointPlan* plan);

}  // namespace dem
