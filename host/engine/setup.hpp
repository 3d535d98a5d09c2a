#pragma once
/// A simulation from a config: the [solver] settings, the `run` job's box of balls, the snapshot of a state for
/// the output files, and the benchmark packing. The jobs above build on these.
#include <memory>
#include <string>

#include "host/config/config.hpp"
#include "host/io/io_hdf5.hpp"
#include "host/engine/simulation.hpp"

namespace dem {

/// The [solver] settings as simulation parameters (gravity, damping, density scaling, skin, blow-up limit);
/// the domain is left open (non-periodic).
SimParams solver_params(const Config& cfg);
/// [solver] stats_every, with 0 resolved for this build (SolverConfig::stats_every).
int stats_every_of(const SolverConfig& solver);

/// The simulation a config describes (particles, box walls, materials, time step). Prints the time
/// step it chose and why.
std::unique_ptr<Simulation> build_simulation(const Config& cfg, bool verbose);

/// Particle state for io::Output (host copy, sorted by gid).
io::Snapshot take_snapshot(Simulation& sim, const std::string& label);

/// The benchmark packing of `base`'s beads and contact laws: side^3 balls of the config's diameter in a jittered
/// cubic array pressed to a pitch of 0.995 d (about 6 contacts each), no gravity; periodic on every axis, or between
/// six plane walls that touch the outer layers. perf/bench_engine times it, and `check` measures its speed.
Config packed_lattice(const Config& base, int side, bool periodic);

}  // namespace dem
