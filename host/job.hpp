#pragma once
/// The `run` job: a box of balls built from a config, run for [run] steps with time series,
/// snapshots (HDF5 + XDMF for ParaView) and a progress line.
#include <memory>

#include "config.hpp"
#include "host/io_hdf5.hpp"
#include "host/specimen.hpp"
#include "simulation.hpp"

namespace dem {

/// The [solver] settings as simulation parameters (gravity, damping, density scaling, skin, blow-up limit);
/// the domain is left open (non-periodic).
SimParams solver_params(const Config& cfg);

/// The simulation a config describes (particles, box walls, materials, time step). Prints the time
/// step it chose and why.
std::unique_ptr<Simulation> build_simulation(const Config& cfg, bool verbose);

/// Particle state for io::Output (host copy, sorted by gid).
io::Snapshot take_snapshot(Simulation& sim, const std::string& label);

/// Runs the job, writing OUT/checkpoint.h5 every [run] checkpoint_every steps or checkpoint_minutes, at a
/// SIGINT or SIGTERM and at the end. `resume`: continues from that checkpoint to [run] steps, bit for bit
/// the run that was not stopped. `stop_at_step` >= 0: stop with a checkpoint after that step. Returns 0 on
/// success, 2 on a blow-up (after saving a snapshot and the state for inspection), 128 + the signal when
/// stopped by one, 3 at stop_at_step.
int run_job(const Config& cfg, bool resume = false, long stop_at_step = -1);

/// The benchmark packing of `base`'s beads and contact laws: side^3 balls of the config's diameter in a jittered
/// cubic array pressed to a pitch of 0.995 d (about 6 contacts each), no gravity; periodic on every axis, or between
/// six plane walls that touch the outer layers. perf/bench_engine times it, and `check` measures its speed.
Config packed_lattice(const Config& base, int side, bool periodic);

/// `triaxdem check`: validates the config and describes the job it is for (a membrane triaxial test when it has
/// [specimen], a periodic cell when it has [periodic], else the `run` job's box): balls, geometry, stages, the time
/// step of its beads and laws, steps, and a wall-time estimate from the speed measured on a box of its beads.
int check_job(const Config& cfg);

/// Writes layers.csv (each layer's void ratio in the finished specimen) and porosity_profile.csv.
void write_specimen_report(const std::string& folder, const Config& cfg, const Specimen& sp);

/// Builds the [specimen] of a config by multilayer compaction and writes it (snapshot, layers.csv with
/// the void ratio of each layer, porosity_profile.csv). Returns 0 on success, 2 on a blow-up.
int specimen_job(const Config& cfg);

}  // namespace dem
