#pragma once
/// The records of a membrane test's shear stage (host/triax/triaxial.cpp): at each record the boundary's stresses and
/// strains and the stress measures on the stepping thread, the rest from a copy of the state (record_work.hpp); the
/// snapshots at the paper's points A-D.
#include <array>
#include <string>
#include <vector>

#include "host/config/config.hpp"
#include "host/engine/state_copy.hpp"
#include "host/io/io_hdf5.hpp"
#include "host/triax/record_work.hpp"
#include "host/triax/triaxial.hpp"
#include "host/triax/triaxial_cell.hpp"
#include "host/triax/triaxial_state.hpp"
#include "host/util/progress.hpp"

namespace dem {

/// What a shear stage's records need besides the step: the test, its state and result, the output, the consolidated
/// height and volumes the strains are taken from, and where the records' copies and work are kept.
struct ShearRecorder {
  const Config& cfg;
  const Cell& cell;
  Stage& st;
  TriaxialResult& res;
  io::Output* out;
  Real h0, v0, v0_envelope;
  const std::array<Real, kSnapshotStrains>& snaps;  ///< the strains of the paper's points A-D
  Progress& progress;
  StateCopies& copies;
  RecordWork& work;
  bool verbose;
};

/// The state step k of the shear left: its record where one is due (or `last`), and a snapshot where one is.
void observe_shear(const ShearRecorder& sh, long k, bool last);

/// The series' columns: the boundary's, then the micromechanics' of the specimen and of its central cube where enabled.
std::vector<std::string> series_columns(const MicroConfig& mc);

}  // namespace dem
