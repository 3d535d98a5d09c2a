#pragma once
/// Checkpoints: a Simulation's state and what the job steering it needs to go on, in one HDF5 file
/// written through a temporary file and a rename, so that a run killed at any moment leaves the previous
/// complete checkpoint in place.
///
/// Layout (every dataset at the root): step (int64), time_s, dt_s, cell_pressure_Pa, wall_disp_m,
/// stats (unbalanced, kinetic, max_disp2, max_move2), flags (fresh, bad), domain (lo, hi, strain rate: 3 x 3), periodic
/// (3); per ball (local order) x, v, w, f, m, x_ref (n x 3), radius, mass, inertia, gid, specimen, material;
/// per contact list (balls_*, walls_*): key, i, j, fs, mr, the history slots (slip, twist: kHistorySlotNames), flags,
/// fc, mt, fn; wall_point, wall_velocity,
/// node_x, node_v; the job's arrays as number_<name> (double) and text_<name> (bytes), their names in the
/// root attributes `numbers` and `texts`; counts (balls, ball-ball and ball-wall contacts, walls, mesh nodes); the
/// root attributes `format` ("triaxdem checkpoint 2"), `job`, `config` (the config's fingerprint) and `checksum`
/// (over every dataset and attribute but format and itself).
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "host/io/io_hdf5.hpp"
#include "host/engine/sim_state.hpp"
#include "host/engine/simulation.hpp"

namespace dem {

struct Checkpoint {
  std::string job;                                      ///< the job that wrote it ("run", ...)
  SimState sim;
  std::map<std::string, std::vector<double>> numbers;   ///< the job's state: counters, records so far
  std::map<std::string, std::string> texts;             ///< the job's state in words (e.g. the snapshot index)
  std::string config;                                   ///< the fingerprint of the config that ran it (Config)
};

/// The part every job's checkpoint shares: the job name, the simulation's state and, when `out` is given, the
/// output's series rows and snapshot index.
Checkpoint checkpoint_of(const std::string& job, const Simulation& sim, const io::Output* out,
                         const std::string& config = "");
/// The checkpoint a `--resume` continues from: refuses a missing file (saying how to start afresh), one written by
/// another job and one written with another config (fingerprints that differ; one built in code has none).
Checkpoint resume_checkpoint(const std::string& path, const std::string& job, const std::string& config = "");
/// Puts a simulation and an output (may be null) back where the checkpoint left them.
void resume_from(const Checkpoint& c, Simulation& sim, io::Output* out);

/// Writes atomically; throws std::runtime_error naming the path.
void write_checkpoint(const std::string& path, const Checkpoint& c);
/// Throws std::runtime_error naming the file and what is missing or malformed: another format version, a
/// dataset of another shape, a checksum that does not match (an edited or damaged file), arrays whose rows
/// disagree with the declared counts. The values' ranges are checked when they are restored (check_state).
Checkpoint read_checkpoint(const std::string& path);

/// The name of a run folder's checkpoint, and of the state saved at a blow-up (for inspection, never resumed
/// from by default: the last good checkpoint stays).
std::string checkpoint_path(const std::string& folder);
std::string blowup_path(const std::string& folder);
/// What a blow-up of `job` leaves in `out`'s folder for inspection: the series so far, a snapshot of the balls, and the
/// state at blowup_path (a checkpoint of `job`, written with `config`'s fingerprint).
void save_blowup_state(io::Output& out, Simulation& sim, const std::string& job, const std::string& config);

/// When to write the next checkpoint: every `every_steps` steps (0: never by count) or `minutes` of wall
/// time (0: never by time), whichever comes first.
class CheckpointClock {
 public:
  CheckpointClock(long every_steps, double minutes);
  bool due(long step) const;
  void written();               ///< restarts the wall-time interval
 private:
  long every_;
  double seconds_;
  double last_;
};

/// How a long job checkpoints: where, how often, whether it continues from a checkpoint, and where to stop.
struct CheckpointPlan {
  std::string path;                    ///< the checkpoint file ("": none is written)
  CheckpointClock clock{0, 0};
  const Checkpoint* from = nullptr;    ///< continue from this
  long stop_at_step = -1;              ///< write a checkpoint after this step and stop (a batch slot's end)
  std::string config;                  ///< the config's fingerprint, written into every checkpoint
  /// Due now, after step `step` has been taken: by the clock, a signal or stop_at_step.
  bool due(long step) const;
  /// Whether the job must stop after this checkpoint.
  bool stop(long step) const;
};

/// Thrown by a job that stopped after writing a checkpoint (a signal or stop_at_step); what() says where and
/// how to go on; `code` is the exit status (128 + signal, or 3).
struct RunStopped : std::runtime_error {
  RunStopped(const std::string& what, int code) : std::runtime_error(what), code(code) {}
  int code;
};
/// The RunStopped of a plan that stopped after `step`.
RunStopped run_stopped(const CheckpointPlan& plan, long step);

/// SIGINT and SIGTERM, caught for the lifetime of the object: the run loop polls `requested()`, writes a
/// checkpoint and stops cleanly. The previous handlers come back on destruction.
class StopSignals {
 public:
  StopSignals();
  ~StopSignals();
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;
  static bool requested();
  static int signal();          ///< the signal caught (0: none)
  static const char* name();    ///< "SIGINT", "SIGTERM" or ""
};

}  // namespace dem
