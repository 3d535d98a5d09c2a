#pragma once
/// The `run` job: a box of balls built from a config, run for [run] steps with time series,
/// snapshots (HDF5 + XDMF for ParaView) and a progress line.
#include "host/config/config.hpp"

namespace dem {

/// Runs the job, writing OUT/checkpoint.h5 every [run] checkpoint_every steps or checkpoint_minutes, at a
/// SIGINT or SIGTERM and at the end. `resume`: continues from that checkpoint to [run] steps, bit for bit
/// the run that was not stopped. `stop_at_step` >= 0: stop with a checkpoint after that step. Returns 0 on
/// success, 2 on a blow-up (after saving a snapshot and the state for inspection), 128 + the signal when
/// stopped by one, 3 at stop_at_step.
int run_job(const Config& cfg, bool resume = false, long stop_at_step = -1);

/// `triaxdem check`: validates the config and describes the job it is for (a membrane triaxial test when it has
/// [specimen], a periodic cell when it has [periodic], else the `run` job's box): balls, geometry, stages, the time
/// step of its beads and laws, steps, and a wall-time estimate from the speed measured on a box of its beads.
int check_job(const Config& cfg);

/// Builds the [specimen] of a config by multilayer compaction and writes it (snapshot, layers.csv with
/// the void ratio of each layer, porosity_profile.csv). Returns 0 on success, 2 on a blow-up.
int specimen_job(const Config& cfg);

}  // namespace dem
