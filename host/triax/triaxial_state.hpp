#pragma once
/// What a triaxial run's checkpoint holds besides the simulation (host/triax/triaxial.cpp): the stage and its step,
/// the references fixed at the end of consolidation, the records and micromechanics so far, the output.
#include <string>
#include <vector>

#include "host/engine/checkpoint.hpp"
#include "host/io/io_hdf5.hpp"
#include "host/engine/simulation.hpp"
#include "host/triax/triaxial.hpp"

namespace dem {

/// Snapshots of a triaxial run's shear (0%, 1%, 5% and the end), and the most steps a stage may have.
inline constexpr int kSnapshotStrains = 4;
inline constexpr double kMaxStageSteps = 1e15;

/// Where a triaxial run stands. Numbers only (counters as Real), so that the stage is one array of the file.
struct Stage {
  bool shear = false;             ///< false: consolidation
  long step = 0;                  ///< the steps the stage has taken
  Real h0 = 0, v0 = 0, v0_envelope = 0, void_ratio = 0;  ///< m, m^3, m^3, -: at the end of consolidation
  long consolidation_steps = 0;
  Real q_max = -INFINITY;         ///< Pa, the highest record so far
  int next_snap = 0;              ///< index of the next snapshot strain
  Real next_record = 0;           ///< strain
};

/// Writes the checkpoint of a triaxial run to `path`.
void save_triaxial(const std::string& path, const Simulation& sim, const io::Output* out, const Stage& st,
                   const TriaxialResult& res, const std::string& config = "");
/// Continues from a checkpoint: the simulation, the stage, the records and micromechanics, the output.
/// Throws std::runtime_error naming `path` when it is not a triaxial checkpoint or is malformed.
void restore_triaxial(const Checkpoint& c, const std::string& path, Simulation& sim, io::Output* out, Stage& st,
                      TriaxialResult& res);

}  // namespace dem
