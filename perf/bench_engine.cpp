/// Time loop under load on the reference packing: 54,872 balls of 2 mm (a 38^3 jittered cubic
/// array pressed to a pitch of 0.995 d, so about 6 contacts per ball), periodic, and the same between
/// plane walls. Reports particle-steps per second, contacts per particle and bytes per particle.
/// Run: OMP_NUM_THREADS=2 OMP_PROC_BIND=spread OMP_PLACES=threads ./build/perf/bench_engine
#include <benchmark/benchmark.h>

#include <Kokkos_Core.hpp>

#include "host/cli/job.hpp"
#include "host/engine/setup.hpp"

namespace {

dem::Config packing_config(int side, bool periodic) {
  dem::Config c;
  c.path = "<bench>";
  c.particles.diameter = 2e-3;
  c.ball.mu_s = 0.3;
  c.ball.mu_r = 0.02;
  c.wall = c.ball;
  return dem::packed_lattice(c, side, periodic);
}

std::size_t bytes_per_particle(dem::Simulation& sim) {
  const auto& p = sim.particles();
  // x, v, w, f, m, x_ref; radius, mass, inertia; gid; specimen, material; owner range; 2 adjacency offsets
  const std::size_t per_particle = 6 * 3 * sizeof(double) + 3 * sizeof(double) + sizeof(std::uint32_t) +
                                   2 * sizeof(int) + 2 * sizeof(int) + 2 * sizeof(int);
  const auto& b = sim.ball_contacts();
  const auto& w = sim.wall_contacts();
  // key, i, j, fs, mr, fc, mo, mt, flags, slip, fn, adjacency entry (+ owner ranges, per particle above)
  const std::size_t per_contact = 8 + 4 + 4 + 5 * 3 * 8 + 1 + 8 + 8 + 4;
  return per_particle + (b.n + w.n) * per_contact / p.n;
}

void BM_TimeLoop(benchmark::State& state) {
  const bool periodic = state.range(1) != 0;
  auto sim = dem::build_simulation(packing_config(static_cast<int>(state.range(0)), periodic), false);
  sim->run(200);  // settle the first rebuilds and the initial overlaps
  const long steps = 200;
  for (auto _ : state) {
    sim->run(steps);
    Kokkos::fence();
  }
  const auto touch = sim->touching();
  const double n = sim->particles().n;
  state.counters["particle_steps/s"] =
      benchmark::Counter(n * steps * state.iterations(), benchmark::Counter::kIsRate);
  state.counters["contacts/particle"] = (2.0 * touch[0] + touch[1]) / n;
  state.counters["bytes/particle"] = static_cast<double>(bytes_per_particle(*sim));
  state.counters["threads"] = dem::ExecSpace().concurrency();
}

}  // namespace

BENCHMARK(BM_TimeLoop)->Args({38, 1})->Args({38, 0})->Args({12, 1})->Unit(benchmark::kMillisecond)->UseRealTime();

int main(int argc, char** argv) {
  Kokkos::ScopeGuard guard(argc, argv);
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
