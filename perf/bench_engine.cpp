/// Time loop under load on the reference packing: 54,872 balls of 2 mm (a 38^3 jittered cubic
/// array pressed to a pitch of 0.995 d, so about 6 contacts per ball), periodic, and the same between
/// plane walls. Reports particle-steps per second, contacts per particle and bytes per particle.
/// BM_CellBatch: a batch of periodic cells (host/engine/cell_batch.hpp) of side^3 balls each (9: 729, a calibration
/// cell), their particle-steps per second side by side, against BM_TimeLoop's one cell of the same size alone.
/// Run: OMP_NUM_THREADS=2 OMP_PROC_BIND=spread OMP_PLACES=threads ./build/perf/bench_engine
#include <benchmark/benchmark.h>

#include <Kokkos_Core.hpp>

#include "host/cli/job.hpp"
#include "host/engine/cell_batch.hpp"
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

void BM_CellBatch(benchmark::State& state) {
  const int cells = static_cast<int>(state.range(0)), side = static_cast<int>(state.range(1));
  std::vector<std::unique_ptr<dem::Simulation>> made;
  std::vector<const dem::Simulation*> sims;
  for (int s = 0; s < cells; ++s) {
    dem::Config c = packing_config(side, true);
    c.run.seed = 1 + static_cast<unsigned>(s);  // each cell its own jitter
    made.push_back(dem::build_simulation(c, false));
    sims.push_back(made.back().get());
  }
  dem::CellBatch batch(sims);
  const auto run = [&](long n) {
    for (long k = 0; k < n; ++k) batch.step();
  };
  run(200);
  const long steps = 200;
  for (auto _ : state) {
    run(steps);
    Kokkos::fence();
  }
  state.counters["particle_steps/s"] =
      benchmark::Counter(static_cast<double>(batch.balls()) * steps * state.iterations(), benchmark::Counter::kIsRate);
  state.counters["cells"] = cells;
  state.counters["threads"] = dem::ExecSpace().concurrency();
}

}  // namespace

BENCHMARK(BM_TimeLoop)->Args({38, 1})->Args({38, 0})->Args({12, 1})->Args({9, 1})->Args({5, 1})
    ->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_CellBatch)->Args({1, 9})->Args({8, 9})->Args({64, 9})->Args({512, 9})->Args({4, 5})->Args({16, 5})
    ->Unit(benchmark::kMillisecond)->UseRealTime();

int main(int argc, char** argv) {
  Kokkos::ScopeGuard guard(argc, argv);
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
