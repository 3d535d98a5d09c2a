/// What a time step costs besides its arithmetic: kernel launches, allocations and the host's waits for the device
/// (copies, results read on return, fences), counted through Kokkos' tool callbacks (host/util/sync_counts.hpp) on
/// the steps of the run job and of each stage of a membrane test and a periodic cell. A GPU pays for each wait; the
/// goal is none on a step outside records and rebuilds.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

#include "host/cli/job.hpp"
#include "host/config/config.hpp"
#include "host/engine/cell_batch.hpp"
#include "host/engine/packing.hpp"
#include "host/engine/setup.hpp"
#include "host/engine/simulation.hpp"
#include "host/triax/periodic_triaxial.hpp"
#include "host/triax/triaxial.hpp"
#include "host/util/sync_counts.hpp"
#include "test_util.hpp"

using namespace dem;

namespace {

SyncCounts part_of(const StageTiming& t, SyncPart part) { return t.syncs[static_cast<int>(part)]; }

void print_stage(const StageTiming& t) {
  const double n = std::max(1L, t.steps);
  const SyncCounts control = part_of(t, SyncPart::kControl);
  const SyncCounts step = part_of(t, SyncPart::kStep);
  std::printf("%-16s %6ld steps | step: %.2f launches %.3f allocations %.3f copies %.3f results %.3f fences | "
              "control: %.2f launches %.3f copies %.3f results | %.1f syncs, %.1f allocations per rebuild, %.3f record "
              "syncs per step\n",
              t.name.c_str(), t.steps, step.launches / n, step.allocations / n, step.copies / n,
              step.host_results / n, step.fences / n, control.launches / n, control.copies / n,
              control.host_results / n,
              part_of(t, SyncPart::kRebuild).syncs() / std::max(1.0, double(t.parts.rebuilds)),
              part_of(t, SyncPart::kRebuild).allocations / std::max(1.0, double(t.parts.rebuilds)),
              part_of(t, SyncPart::kRecord).syncs() / n);
}

/// The tiny membrane test, specimen and triaxial stages, reading the statistics every `every` steps.
struct MembraneRun {
  std::vector<StageTiming> stages;
  TriaxialResult result;
};
MembraneRun membrane_run(int every) {
  Config c = test::tiny_triaxial_config(0.3, 0.02);
  c.solver.stats_every = every;
  MembraneRun r;
  const Specimen sp = build_specimen(c, false);
  r.stages = sp.stages;
  r.result = run_triaxial(c, sp, nullptr, false);
  for (const StageTiming& t : r.result.stages) r.stages.push_back(t);
  return r;
}

PeriodicTriaxialResult periodic_run(int every) {
  Config cfg = test::tiny_cell_config();
  cfg.solver.stats_every = every;
  auto sim = make_periodic_simulation(make_packing(cfg), cfg.box.size, cfg.ball, cfg.solver);
  PeriodicTriaxialParams p = cfg.periodic.triax;
  p.sigma3 = 100e3;
  p.verbose = false;
  return run_periodic_triaxial(*sim, p);
}

/// A step's own waits (its control's and its records' left out): copies and results read on return, per step. The
/// timers' fences (one step in 16) are counted apart.
double step_waits(const StageTiming& t) {
  const SyncCounts c = part_of(t, SyncPart::kStep);
  return double(c.copies + c.host_results) / double(std::max(1L, t.steps));
}

/// Adds dv (m/s) to the first ball's x velocity. A free function: nvcc takes no device lambda in a test's body.
void kick_first_ball(Particles& p, Real dv) {
  auto v = p.v;
  Kokkos::parallel_for("test::kick", RangePolicy(0, 1), KOKKOS_LAMBDA(const int) { v(0, 0) += dv; });
}

}  // namespace

// The run job's step (walls, 2,000 balls), counted between rebuilds: its forces and leapfrog allocate nothing, and
// with stats_every = 16 the statistics come back once in 16 steps (two copies: the rows and the overlaps).
TEST(HotPath, AStepAllocatesNothingAndReadsItsStatisticsEveryKSteps) {
  Config cfg = load_config(std::string(TRIAXDEM_SOURCE_DIR) + "/configs/default.toml");
  cfg.solver.stats_every = 16;
  auto sim = build_simulation(cfg, false);
  ASSERT_TRUE(count_syncs()) << "a profiling tool holds Kokkos' callbacks";
  for (int k = 0; k < 50; ++k) sim->step(false);
  const long rebuilds = sim->times().rebuilds;
  const int steps = 32;
  const SyncTally before = sync_tally();
  {
    const SyncScope part(SyncPart::kStep);
    for (int k = 0; k < steps; ++k) sim->step(false);
  }
  const SyncCounts c = sync_tally()[static_cast<int>(SyncPart::kStep)] - before[static_cast<int>(SyncPart::kStep)];
  ASSERT_EQ(sim->times().rebuilds, rebuilds) << "a rebuild in the counted steps";
  std::printf("per step: %.2f launches, %.2f allocations, %.3f copies, %.3f results, %.3f fences\n",
              double(c.launches) / steps, double(c.allocations) / steps, double(c.copies) / steps,
              double(c.host_results) / steps, double(c.fences) / steps);
  ASSERT_GT(c.launches, 0) << "the callbacks never fired: Kokkos built without its tools interface";
  EXPECT_EQ(c.allocations, 0);
  EXPECT_EQ(c.host_results, 0);
  // At most a read every 16 steps, of two copies each; a read the bound on the balls' speed asks for adds two.
  EXPECT_LE(c.copies, 2 * (steps / 16) + 2);
  // The part timers fence on one step in 16 (host/engine/simulation.cpp), 6 times at most, and not on the others.
  EXPECT_LE(c.fences, 6 * (steps / 16));
}

// Every stage of the tiny membrane test (specimen layers, consolidation, shear) and of the tiny periodic cell, with
// the statistics read every step and every 16 steps: the same steps bit for bit (the rebuilds decided between reads
// as a read at every step decides them), and the steps' own waits down to the reads. What remains per step is the
// membrane specimen's layers' control (the platen's compaction: docs/engine.md); the servos of the membrane's
// consolidation and of the periodic cell run on the device.
TEST(HotPath, StatisticsReadEvery16StepsGiveTheSameStepsWithFewerWaits) {
  const MembraneRun every1 = membrane_run(1), every16 = membrane_run(16);
  ASSERT_EQ(every1.stages.size(), every16.stages.size());
  for (std::size_t k = 0; k < every1.stages.size(); ++k) {
    const StageTiming &a = every1.stages[k], &b = every16.stages[k];
    print_stage(a);
    print_stage(b);
    EXPECT_EQ(a.steps, b.steps) << a.name;
    EXPECT_EQ(a.parts.rebuilds, b.parts.rebuilds) << a.name;
    EXPECT_EQ(b.parts.late_rebuilds, 0) << a.name;
    EXPECT_EQ(part_of(b, SyncPart::kStep).allocations, 0) << a.name;
    // A rebuild reuses the binning's, the permutation's, the adjacency's, the search's and the contact lists' buffers
    // (kernels/core/buffers.hpp, ListBuffers): it allocates only where a buffer grows, by a quarter at a time, as the
    // contacts of the layers and of a cell compressed from a gas grow (1-5 a rebuild, 0.3 in the membrane's shear).
    // A list made afresh at each rebuild is 24 more, and the rest of the old way 57-59.
    if (b.parts.rebuilds >= 10)
      EXPECT_LE(double(part_of(b, SyncPart::kRebuild).allocations) / double(b.parts.rebuilds), 6.0) << a.name;
    // Read every step: two copies a step. Every 16: two copies in 16 steps, and the reads the rebuilds ask for.
    EXPECT_NEAR(step_waits(a), 2.0, 0.01) << a.name;
    EXPECT_LT(step_waits(b), 0.25) << a.name;
    // The platen servo runs on the device (Simulation::set_wall_servo): the stage's control reads the platens only
    // before a measured step (one in 200) for its check. On the host the servo read them and sent the platen's speed,
    // two copies a step.
    if (a.name == "consolidation") {
      const SyncCounts control = part_of(b, SyncPart::kControl);
      EXPECT_LE(double(control.copies + control.host_results) / double(b.steps), 1.0 / 200 + 1e-9) << a.name;
    }
  }
  const std::vector<TriaxialRecord>&r1 = every1.result.records, &r16 = every16.result.records;
  ASSERT_EQ(r1.size(), r16.size());
  ASSERT_FALSE(r1.empty());
  for (std::size_t k = 0; k < r1.size(); ++k) {
    EXPECT_EQ(r1[k].q, r16[k].q) << "record " << k;
    EXPECT_EQ(r1[k].eps_v, r16[k].eps_v) << "record " << k;
    EXPECT_EQ(r1[k].unbalanced, r16[k].unbalanced) << "record " << k;
  }

  const PeriodicTriaxialResult p1 = periodic_run(1), p16 = periodic_run(16);
  ASSERT_EQ(p1.stages.size(), p16.stages.size());
  for (std::size_t k = 0; k < p1.stages.size(); ++k) {
    print_stage(p1.stages[k]);
    print_stage(p16.stages[k]);
    EXPECT_EQ(p1.stages[k].steps, p16.stages[k].steps);
    EXPECT_EQ(p1.stages[k].parts.rebuilds, p16.stages[k].parts.rebuilds);
    EXPECT_EQ(p16.stages[k].parts.late_rebuilds, 0);
    EXPECT_LT(step_waits(p16.stages[k]), 0.25);
    // The cell's servo runs on the device (Simulation::set_cell_servo): its control waits for nothing, and its kernels
    // allocate nothing. On the host it read the stress every step and the stiffness every tenth: 1.1 copies a step.
    const SyncCounts control = part_of(p16.stages[k], SyncPart::kControl);
    EXPECT_EQ(control.syncs(), 0) << p16.stages[k].name;
    EXPECT_EQ(control.allocations + part_of(p16.stages[k], SyncPart::kStep).allocations, 0) << p16.stages[k].name;
  }
  ASSERT_EQ(p1.series.size(), p16.series.size());
  for (std::size_t k = 0; k < p1.series.size(); ++k) {
    EXPECT_EQ(p1.series[k].q, p16.series[k].q) << "record " << k;
    EXPECT_EQ(p1.series[k].eps_v, p16.series[k].eps_v) << "record " << k;
  }
}

// The bound between reads can fail: a ball given, between two reads, a speed far above any of the last read's has
// passed half the skin before the next one. The read finds the lists expired steps late, counts it and says so, and
// the rebuild follows at once.
TEST(HotPath, ABallThatOutrunsTheBoundIsALateRebuild) {
  Config cfg = load_config(std::string(TRIAXDEM_SOURCE_DIR) + "/configs/default.toml");
  cfg.solver.stats_every = 64;
  auto sim = build_simulation(cfg, false);
  for (int k = 0; k < 100; ++k) sim->step(false);
  const Real skin = sim->params().skin, dt = sim->params().integ.dt;
  sim->step(true);  // read now: the bound starts from this step's speeds
  ASSERT_EQ(sim->times().late_rebuilds, 0);
  const long rebuilds = sim->times().rebuilds;
  // Half the skin in 8 steps: the bound, from far lower speeds, lets many more steps go unread.
  kick_first_ball(sim->particles(), skin / (16 * dt));
  testing::internal::CaptureStderr();
  for (int k = 0; k < 64; ++k) sim->step(false);
  sim->step(false);  // the rebuild the late read found due
  const std::string said = testing::internal::GetCapturedStderr();
  EXPECT_GE(sim->times().late_rebuilds, 1);
  EXPECT_GT(sim->times().rebuilds, rebuilds);
  EXPECT_NE(said.find("found expired some steps late"), std::string::npos) << said;
}

// A state taken between two reads (state() reads first) and restored into a simulation built alike starts from the
// last step's statistics and goes on bit for bit as the one it was taken from: the restored one reads every step
// until its first read bounds the balls' speed.
TEST(HotPath, AStateTakenBetweenReadsResumesBitForBit) {
  Config cfg = load_config(std::string(TRIAXDEM_SOURCE_DIR) + "/configs/default.toml");
  cfg.solver.stats_every = 16;
  auto sim = build_simulation(cfg, false);
  for (int k = 0; k < 37; ++k) sim->step(false);  // 37: in the middle of a read's 16 steps
  const SimState state = sim->state();
  const long rebuilds_before = sim->times().rebuilds;
  auto resumed = build_simulation(cfg, false);
  resumed->restore(state);
  // The statistics it starts from are step 37's, read by state(), not those of the read before.
  EXPECT_EQ(resumed->stats().max_disp2, sim->stats().max_disp2);
  EXPECT_GT(resumed->stats().max_disp2, 0);
  // On until the restored one has rebuilt twice: its first rebuild is decided from the restored state.
  for (int k = 0; k < 20000 && resumed->times().rebuilds < 2; ++k) {
    sim->step(false);
    resumed->step(false);
  }
  ASSERT_GT(resumed->times().rebuilds, 0) << "no rebuild after the restore: the test would show little";
  EXPECT_EQ(sim->times().rebuilds - rebuilds_before, resumed->times().rebuilds);
  const SimState a = sim->state(), b = resumed->state();
  ASSERT_EQ(a.x.size(), b.x.size());
  for (std::size_t k = 0; k < a.x.size(); ++k) ASSERT_EQ(a.x[k], b.x[k]) << "coordinate " << k;
  EXPECT_EQ(a.wall_disp, b.wall_disp);
}

namespace {

/// A batch step's waits: `cells` periodic lattices of 125 balls, steps 22-37 (no rebuild), counted per step; with
/// `servoed`, each cell's three axes servoed on the device from step 21 (a slow one: the lattice barely moves).
SyncCounts batch_step_waits(int cells, bool servoed = false) {
  std::vector<std::unique_ptr<Simulation>> made;
  std::vector<const Simulation*> sims;
  for (int s = 0; s < cells; ++s) {
    Config c = test::tiny_cell_config();
    c.run.seed = 1 + static_cast<unsigned>(s);
    made.push_back(build_simulation(packed_lattice(c, 5, true), false));
    sims.push_back(made.back().get());
  }
  CellBatch batch(sims);
  for (int k = 0; k < 20; ++k) batch.step();
  if (servoed) {
    CellServoSpec spec;
    for (bool& on : spec.servo) on = true;
    spec.sigma3 = 1e3;
    spec.alpha = 0.5;
    spec.max_rate = 1e-3;
    spec.stiffness_every = 10;
    for (int s = 0; s < cells; ++s) batch.set_cell_servo(s, spec);
  }
  batch.step();  // the cells start stretching: the device learns which
  const long rebuilds = batch.rebuild_steps();
  const SyncTally before = sync_tally();
  {
    const SyncScope part(SyncPart::kStep);
    for (int k = 0; k < 16; ++k) batch.step();
  }
  EXPECT_EQ(batch.rebuild_steps(), rebuilds) << "a rebuild in the counted steps";
  return sync_tally()[static_cast<int>(SyncPart::kStep)] - before[static_cast<int>(SyncPart::kStep)];
}

}  // namespace

// A batch's step waits for the host as often whatever the number of its cells: one launch per kernel and one copy
// of the statistics for all of them, and no allocation.
TEST(HotPath, ABatchStepWaitsAsOftenForSixCellsAsForTwo) {
  ASSERT_TRUE(count_syncs()) << "a profiling tool holds Kokkos' callbacks";
  const SyncCounts two = batch_step_waits(2), six = batch_step_waits(6);
  std::printf("a batch step: %.2f launches, %.2f copies, %.2f results, %.2f allocations (2 cells); %.2f, %.2f, %.2f, "
              "%.2f (6 cells)\n", two.launches / 16.0, two.copies / 16.0, two.host_results / 16.0,
              two.allocations / 16.0, six.launches / 16.0, six.copies / 16.0, six.host_results / 16.0,
              six.allocations / 16.0);
  EXPECT_EQ(six.launches, two.launches);
  EXPECT_EQ(six.copies, two.copies);
  EXPECT_EQ(six.host_results, two.host_results);
  EXPECT_EQ(six.allocations, 0);
  EXPECT_LE(six.copies + six.host_results, 2 * 16) << "the statistics, and the count of overlaps past their limits";
  // Servoed on the device, the cells add launches (the stress's and, on one step in ten, the stiffness's reductions,
  // the rates, the stretch) and no wait: on the host their servo read the stresses and sent the rates, two copies a
  // step.
  const SyncCounts servoed = batch_step_waits(6, true);
  std::printf("a servoed batch step: %.2f launches, %.2f copies, %.2f results, %.2f allocations (6 cells)\n",
              servoed.launches / 16.0, servoed.copies / 16.0, servoed.host_results / 16.0, servoed.allocations / 16.0);
  EXPECT_EQ(servoed.copies + servoed.host_results, six.copies + six.host_results);
  EXPECT_EQ(servoed.allocations, 0);
  EXPECT_GT(servoed.launches, six.launches);
}

namespace {

/// Each particle's force and moment summed on the host from the contact lists, in the order Gather sums them
/// (accumulate.hpp): its own ball-ball contacts in key order, the reactions of the others in list order, its wall
/// contacts in list order.
void host_gather(const Simulation& sim, std::vector<Vec3>& f, std::vector<Vec3>& m) {
  const int n = sim.particles().n;
  f.assign(n, Vec3());
  m.assign(n, Vec3());
  auto h = [](const auto& v) { return Kokkos::create_mirror_view_and_copy(HostSpace(), v); };
  const ContactList &b = sim.ball_contacts(), &wc = sim.wall_contacts();
  auto bi = h(b.i), bj = h(b.j);
  auto fc = h(b.fc), mo = h(b.mo), mt = h(b.mt);
  for (int s = 0; s < b.n; ++s) {
    f[bi(s)] += load(fc, s);
    m[bi(s)] += load(mo, s);
  }
  for (int s = 0; s < b.n; ++s) {
    f[bj(s)] -= load(fc, s);
    m[bj(s)] += load(mt, s);
  }
  auto wi = h(wc.i);
  auto wfc = h(wc.fc), wmt = h(wc.mt);
  for (int s = 0; s < wc.n; ++s) {
    f[wi(s)] += load(wfc, s);
    m[wi(s)] += load(wmt, s);
  }
}

}  // namespace

// A step does not store the balls' forces and moments (48 bytes a ball; only output and states read them):
// particles_with_forces gathers the last step's on demand, the same bits as the contact lists summed in the gather's
// order, and again after further steps (it fails where a step's forces are left stale, or a step still stores them).
TEST(HotPath, AStepLeavesTheForcesToOutputWhichGathersTheLastStepsOnDemand) {
  // The benchmark's packing between walls, 8^3 balls: about 6 contacts each, and wall contacts on the outer layers.
  const Config cfg = packed_lattice(load_config(std::string(TRIAXDEM_SOURCE_DIR) + "/configs/default.toml"), 8, false);
  auto sim = build_simulation(cfg, false);
  const auto zero = [](const Vec3& a) { return a.x == 0 && a.y == 0 && a.z == 0; };
  const auto same = [](const Vec3& a, const Vec3& b) { return std::memcmp(&a, &b, sizeof(Vec3)) == 0; };
  const auto zeros = [&](const Vec3View& v) {
    auto h = Kokkos::create_mirror_view_and_copy(HostSpace(), v);
    for (std::size_t i = 0; i < h.extent(0); ++i)
      if (!zero(load(h, static_cast<int>(i)))) return false;
    return true;
  };
  ASSERT_TRUE(zeros(sim->particles().f));
  for (int round = 0; round < 2; ++round) {
    sim->run(40);
    EXPECT_TRUE(zeros(sim->particles().f)) << "a step stored the forces";
    EXPECT_TRUE(zeros(sim->particles().m)) << "a step stored the moments";
    std::vector<Vec3> f, m;
    host_gather(*sim, f, m);
    const Particles& p = sim->particles_with_forces();
    auto hf = Kokkos::create_mirror_view_and_copy(HostSpace(), p.f);
    auto hm = Kokkos::create_mirror_view_and_copy(HostSpace(), p.m);
    int nonzero = 0;
    for (int i = 0; i < p.n; ++i) {
      ASSERT_TRUE(same(f[i], load(hf, i))) << "force, particle " << i;
      ASSERT_TRUE(same(m[i], load(hm, i))) << "moment, particle " << i;
      nonzero += !zero(f[i]);
    }
    EXPECT_GT(nonzero, p.n / 2) << "the balls carry forces";
    // Gathered, then zeroed by hand: the next steps must not leave them at zero for output.
    Kokkos::deep_copy(p.f, 0.0);
    Kokkos::deep_copy(p.m, 0.0);
  }
}

// A shear record copies the state into kept host buffers (host/engine/state_copy.hpp: deep copies into buffers of
// their own, which a CPU build allocates and fills as a GPU build does, where mirrors would be the device's own Views
// on a CPU and hide their cost): after the first records, one buffer set at once and a second where the records are
// worked out beside the steps, a record allocates nothing, and what it copies is the same for every record. Counted
// on the shear's control (where the records are taken) of the tiny membrane test with twice the records: the run
// with more records may allocate more only where a list outgrows its buffer, by a quarter at a time.
TEST(HotPath, AShearRecordCopiesTheStateIntoKeptBuffersAndAllocatesNothing) {
  Config c = test::tiny_triaxial_config(0.3, 0.02);
  c.solver.stats_every = 16;
  const Specimen sp = build_specimen(c, false);
  for (const char* overlap : {"off", "on"}) {
    SyncCounts control[2];
    std::size_t records[2];
    for (int more : {0, 1}) {
      c.micro.overlap = overlap;
      c.triaxial.record_every = more ? 0.0025 : 0.005;
      const TriaxialResult r = run_triaxial(c, sp, nullptr, false);
      control[more] = part_of(r.stages.back(), SyncPart::kControl);
      records[more] = r.records.size();
    }
    const double extra = double(records[1] - records[0]);
    ASSERT_GT(extra, 10) << overlap;
    const double copies = double(control[1].copies - control[0].copies) / extra;
    const double allocations = double(control[1].allocations - control[0].allocations) / extra;
    std::printf("[micro] overlap %s: %zu and %zu records; a record: %.2f copies, %.2f allocations (%ld and %ld in "
                "all)\n", overlap, records[0], records[1], copies, allocations, control[0].allocations,
                control[1].allocations);
    // The state's arrays (balls, contact lists, walls, the membrane's nodes; its facets only at the first records)
    // and the wall loads: some twenty copies, the same number each record (a kept buffer is filled, never remade),
    // and two more for each of the six 3-vector arrays where their rows are three columns (LayoutLeft, a GPU build's:
    // copy_rows copies each column).
    const int more_columns = std::is_same<Layout, Kokkos::LayoutRight>::value ? 0 : 12;
    EXPECT_EQ(copies, std::round(copies)) << overlap;
    EXPECT_GT(copies, 15 + more_columns) << overlap;
    EXPECT_LT(copies, 25 + more_columns) << overlap;
    EXPECT_LE(allocations, 0.05) << overlap;
  }
}
