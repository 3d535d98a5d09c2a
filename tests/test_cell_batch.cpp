// Periodic cells stepped side by side (host/engine/cell_batch.hpp): each specimen's steps bit for bit those of its
// own Simulation, whatever the others do (other sizes, laws, rates, a stop, a blow-up). Specimens of 100-140 balls
// of 2 mm from a gas (solid fraction 0.1), compressed at fixed strain rates through first contact into a dense
// packing and then sheared: the neighbour lists are rebuilt dozens of times, at other steps in each specimen alone.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "host/engine/cell_batch.hpp"
#include "host/engine/packing.hpp"
#include "host/triax/periodic_triaxial.hpp"
#include "test_util.hpp"

using namespace dem;

namespace {

/// A specimen's recipe: balls and seed, its law's friction and stiffness, and its program's strains over the steps
/// of each phase (rates from its own time step).
struct Recipe {
  int balls;
  unsigned seed;
  Real mu_s, emod;
  Real squeeze, shear;  ///< isotropic compression, then axial compression (lateral extension at half)
};

std::unique_ptr<Simulation> make_cell(const Recipe& r) {
  Config cfg = test::tiny_cell_config();
  cfg.particles.count = r.balls;
  const Real L = std::cbrt(r.balls * M_PI / 6 * 8e-9 / 0.1);
  cfg.box.size = {L, L, L};
  cfg.run.seed = r.seed;
  ContactParams law = cfg.ball.base();
  law.mu_s = r.mu_s;
  law.emod = r.emod;
  return make_periodic_simulation(make_packing(cfg), cfg.box.size, law, cfg.solver);
}

constexpr long kSteps = 9000, kSqueeze = 6000;

/// The program's strain rate (1/s) at step n, for a specimen of time step dt.
Vec3 rate_at(const Recipe& r, long n, Real dt) {
  if (n < kSqueeze) {
    const Real e = r.squeeze / (kSqueeze * dt);
    return Vec3(-e, -e, -e);
  }
  const Real e = r.shear / ((kSteps - kSqueeze) * dt);
  return Vec3(0.5 * e, 0.5 * e, -e);
}

bool same_bits(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(Vec3)) == 0;
}

/// What a specimen's run leaves: its balls, its stress, its steps and rebuilds, and the blow-up that stopped it.
struct Outcome {
  HostParticles balls;
  std::array<Real, 3> stress{};
  long steps = 0, rebuilds = 0;
  std::string blowup;
};

/// Steps 0 .. `steps` - 1 of the program alone, until a blow-up; every 7th step measured. The time step times
/// `dt_factor`, the rates those of the time step made.
Outcome alone(const Recipe& r, long steps, Real dt_factor = 1) {
  auto sim = make_cell(r);
  const Real dt = sim->params().integ.dt;
  sim->set_dt(dt_factor * dt);
  Outcome o;
  try {
    for (long n = 0; n < steps; ++n) {
      sim->set_strain_rate(rate_at(r, n, dt));
      sim->step(n % 7 == 0);
    }
  } catch (const BlowUp& e) {
    o.blowup = e.what();
  }
  o.balls = to_host_by_gid(sim->particles());
  o.stress = sim->contact_stress_diagonal(sim->domain().volume());
  o.steps = sim->step_count();
  o.rebuilds = sim->times().rebuilds;
  return o;
}

void expect_same(const Outcome& want, const CellBatch& batch, int s, const std::array<Real, 3>& stress) {
  const HostParticles got = batch.balls_of(s);
  EXPECT_TRUE(same_bits(got.x, want.balls.x)) << "specimen " << s << ": positions";
  EXPECT_TRUE(same_bits(got.v, want.balls.v)) << "specimen " << s << ": velocities";
  EXPECT_TRUE(same_bits(got.w, want.balls.w)) << "specimen " << s << ": spins";
  // Rebuilt with the others when one is due: as often as the fastest alone, which changes no bit.
  if (batch.running(s)) EXPECT_GE(batch.rebuilds(s), want.rebuilds) << "specimen " << s;
  EXPECT_EQ(batch.blowup(s), want.blowup) << "specimen " << s;
  if (want.blowup.empty()) {
    EXPECT_EQ(batch.step_count(s), want.steps) << "specimen " << s;
    EXPECT_EQ(std::memcmp(stress.data(), want.stress.data(), sizeof stress), 0)
        << "specimen " << s << ": stress " << stress[2] << " vs " << want.stress[2];
  }
}

const std::vector<Recipe> kRecipes = {
    {100, 11u, 0.3, 1e8, 0.55, 0.03},
    {140, 12u, 0.5, 1e8, 0.54, 0.04},  // more balls, more friction, other strains
    {100, 13u, 0.3, 2e8, 0.55, 0.03},  // stiffer: another time step
};

TEST(CellBatch, EachSpecimenStepsBitForBitAsItsOwnSimulation) {
  std::vector<std::unique_ptr<Simulation>> made;
  std::vector<const Simulation*> sims;
  for (const Recipe& r : kRecipes) {
    made.push_back(make_cell(r));
    sims.push_back(made.back().get());
  }
  CellBatch batch(sims);
  std::vector<char> measure(kRecipes.size());
  for (long n = 0; n < kSteps; ++n) {
    for (int s = 0; s < batch.size(); ++s) batch.set_strain_rate(s, rate_at(kRecipes[s], n, sims[s]->params().integ.dt));
    std::fill(measure.begin(), measure.end(), n % 7 == 0);
    batch.step(measure);
  }
  const auto stress = batch.contact_stress_diagonals();
  std::vector<long> alone_rebuilds;
  for (int s = 0; s < batch.size(); ++s) {
    const Outcome want = alone(kRecipes[s], kSteps);
    alone_rebuilds.push_back(want.rebuilds);
    ASSERT_TRUE(want.blowup.empty()) << want.blowup;
    // The program makes a packing that carries load (0.4-3 kPa axially) and rebuilds the lists many times.
    EXPECT_GT(want.stress[2], 100) << "specimen " << s;
    EXPECT_GT(want.rebuilds, 20) << "specimen " << s;
    expect_same(want, batch, s, stress[s]);
    EXPECT_TRUE(batch.running(s));
  }
  // Rebuilt together, and at other steps than some of them alone.
  for (int s = 0; s < batch.size(); ++s) EXPECT_EQ(batch.rebuilds(s), batch.rebuild_steps()) << "specimen " << s;
  EXPECT_GT(batch.rebuild_steps(), *std::min_element(alone_rebuilds.begin(), alone_rebuilds.end()));
}

// A specimen stopped part way keeps its state; two alike whose time step is five times too large blow up at the same
// step, each stopped with its own Simulation's message (one's larger overlap hides nothing of the other's), and the
// others finish as they would alone.
TEST(CellBatch, AStoppedOrBlownUpSpecimenLeavesTheOthersAsTheyWouldBeAlone) {
  std::vector<Recipe> recipes = kRecipes;
  recipes.push_back(kRecipes[2]);  // specimen 3: specimen 2 again
  std::vector<std::unique_ptr<Simulation>> made;
  std::vector<const Simulation*> sims;
  std::vector<Real> dt;  // the rates': the time steps made
  for (std::size_t s = 0; s < recipes.size(); ++s) {
    made.push_back(make_cell(recipes[s]));
    dt.push_back(made.back()->params().integ.dt);
    if (s >= 2) made.back()->set_dt(5 * dt.back());
    sims.push_back(made.back().get());
  }
  CellBatch batch(sims);
  const long stop_at = 4000;
  for (long n = 0; n < kSteps; ++n) {
    if (n == stop_at) batch.stop(1);
    for (int s = 0; s < batch.size(); ++s) batch.set_strain_rate(s, rate_at(recipes[s], n, dt[s]));
    batch.step(std::vector<char>(recipes.size(), n % 7 == 0));
  }
  const auto stress = batch.contact_stress_diagonals();
  expect_same(alone(kRecipes[0], kSteps), batch, 0, stress[0]);
  const Outcome stopped = alone(kRecipes[1], stop_at);
  expect_same(stopped, batch, 1, stress[1]);
  EXPECT_FALSE(batch.running(1));
  const Outcome blown = alone(kRecipes[2], kSteps, 5);
  ASSERT_FALSE(blown.blowup.empty()) << "the time step five times too large must blow up alone";
  ASSERT_NE(blown.blowup.find("overlaps"), std::string::npos) << "an overlap's blow-up: " << blown.blowup;
  for (int s : {2, 3}) {
    expect_same(blown, batch, s, stress[static_cast<std::size_t>(s)]);
    EXPECT_FALSE(batch.running(s));
  }
  EXPECT_EQ(batch.running_count(), 1);
}

TEST(CellBatch, SpecimensThatCannotShareABatchAreRefusedByIndexAndReason) {
  auto periodic = make_cell(kRecipes[0]);
  Config walled = test::tiny_cell_config();
  auto cuboid = make_periodic_simulation(make_packing(walled), walled.box.size, walled.ball, walled.solver,
                                         CellBoundary::walls);
  try {
    CellBatch batch({periodic.get(), cuboid.get()});
    FAIL() << "a walled cuboid was taken into a batch of periodic cells";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("specimen 1"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("periodic"), std::string::npos) << e.what();
  }
  periodic->step();
  EXPECT_THROW(CellBatch({periodic.get()}), std::invalid_argument);
  EXPECT_THROW(CellBatch(std::vector<const Simulation*>{}), std::invalid_argument);
}

/// The tiny cell's packing with `seed`, as a fresh Simulation with friction mu_s.
std::unique_ptr<Simulation> tiny_cell(unsigned seed, Real mu_s) {
  Config cfg = test::tiny_cell_config();
  cfg.run.seed = seed;
  ContactParams law = cfg.ball.base();
  law.mu_s = mu_s;
  return make_periodic_simulation(make_packing(cfg), cfg.box.size, law, cfg.solver);
}

PeriodicTriaxialParams tiny_test(Real sigma3) {
  PeriodicTriaxialParams p = test::tiny_cell_config().periodic.triax;
  p.sigma3 = sigma3;
  p.verbose = false;
  return p;
}

// The whole periodic test (servoed consolidation from a gas, then shear with records) of three specimens of other
// packings, friction and pressures, side by side, and of the second alone: each one's curves, steps and consolidation
// those of its own run. Alone, a specimen's lists are rebuilt at its own pace, within steps whose cell the servo on the
// device changed (a host that took the rebuild's read of the cell for the step's end missed the stretch after it).
TEST(CellBatch, PeriodicTestsSideBySideGiveEachItsOwnRunsRecords) {
  const std::vector<unsigned> seeds = {21u, 22u, 23u};
  const std::vector<Real> mu = {0.3, 0.5, 0.3}, sigma3 = {100e3, 100e3, 200e3};
  for (const std::vector<std::size_t>& members : {std::vector<std::size_t>{0, 1, 2}, std::vector<std::size_t>{1}}) {
    std::vector<std::unique_ptr<Simulation>> made;
    std::vector<Simulation*> sims;
    std::vector<PeriodicTriaxialParams> prms;
    for (std::size_t s : members) {
      made.push_back(tiny_cell(seeds[s], mu[s]));
      sims.push_back(made.back().get());
      prms.push_back(tiny_test(sigma3[s]));
    }
    std::array<long, 2> steps{};
    const std::vector<BatchedTest> batch = run_periodic_batch(sims, prms, false, &steps);
    std::printf("the batch of %zu: %ld steps, %ld of them with a rebuild\n", members.size(), steps[0], steps[1]);
    for (std::size_t m = 0; m < members.size(); ++m) {
      const std::size_t s = members[m];
      auto sim = tiny_cell(seeds[s], mu[s]);
      const PeriodicTriaxialResult want = run_periodic_triaxial(*sim, prms[m]);
      const BatchedTest& got = batch[m];
      ASSERT_TRUE(got.blowup.empty() && got.failure.empty()) << got.blowup << got.failure;
      EXPECT_EQ(got.result.consolidation_steps, want.consolidation_steps) << "specimen " << s;
      ASSERT_EQ(got.result.series.size(), want.series.size()) << "specimen " << s;
      ASSERT_GT(want.series.size(), 5u);
      for (std::size_t k = 0; k < want.series.size(); ++k) {
        const PeriodicTriaxialRecord &a = got.result.series[k], &b = want.series[k];
        EXPECT_EQ(a.step, b.step) << "specimen " << s << ", record " << k;
        EXPECT_EQ(a.q, b.q) << "specimen " << s << ", record " << k;
        EXPECT_EQ(a.eps_v, b.eps_v) << "specimen " << s << ", record " << k;
        EXPECT_EQ(a.coordination, b.coordination) << "specimen " << s << ", record " << k;
        EXPECT_EQ(a.unbalanced, b.unbalanced) << "specimen " << s << ", record " << k;
        EXPECT_EQ(a.rate_x, b.rate_x) << "specimen " << s << ", record " << k;
      }
      EXPECT_EQ(got.result.q_peak, want.q_peak) << "specimen " << s;
      EXPECT_GT(want.q_peak, 0.1 * sigma3[s]) << "specimen " << s;  // a test that sheared
      // Each stage's host work is split as a single run's is (timings.csv): its control before a step and its
      // records after one, each measured, so neither is zero.
      ASSERT_EQ(got.result.stages.size(), want.stages.size()) << "specimen " << s;
      for (const StageTiming& t : got.result.stages) {
        EXPECT_GT(t.control, 0.0) << t.name << ", specimen " << s;
        EXPECT_GT(t.after, 0.0) << t.name << ", specimen " << s;
      }
    }
  }
}

}  // namespace
