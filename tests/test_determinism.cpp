/// Bit-for-bit reproducibility across thread counts. Kokkos' OpenMP back end fixes its thread count at
/// initialisation, so the test re-runs this very binary twice as a child process, with
/// OMP_NUM_THREADS=1 and =2, each running the helper test Determinism.HashChild (skipped unless
/// TRIAXDEM_HASH_CHILD=1), and compares the hashes of the final states.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cinttypes>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "host/engine/builder.hpp"
#include "host/engine/packing.hpp"
#include "host/triax/periodic_triaxial.hpp"
#include "host/triax/micro_report.hpp"
#include "host/engine/simulation.hpp"
#include "host/triax/triaxial.hpp"
#include "test_util.hpp"

using namespace dem;

namespace {

/// FNV-1a, 64 bit, over raw bytes.
struct Fnv1a {
  std::uint64_t h = 14695981039346656037ull;
  void add(const void* p, std::size_t n) {
    const unsigned char* b = static_cast<const unsigned char*>(p);
    for (std::size_t k = 0; k < n; ++k) {
      h ^= b[k];
      h *= 1099511628211ull;
    }
  }
  void add(const Vec3& v) {
    const double c[3] = {v.x, v.y, v.z};
    add(c, sizeof c);
  }
};

bool child_mode() {
  const char* e = std::getenv("TRIAXDEM_HASH_CHILD");
  return e != nullptr && std::string(e) == "1";
}

struct ChildReport {
  bool found = false;
  int threads = 0;
  unsigned long long hash = 0;
  long touching = 0, sliding = 0, rolling = 0, rebuilds = 0;
  int status = -1;
  std::string output;
};

/// Runs the helper test `helper` (Determinism.HashChild or .TriaxialHashChild) in a child with `threads` threads.
ChildReport run_child(int threads, const std::string& helper = "HashChild") {
  ChildReport r;
  char exe[4096];
  const ssize_t len = readlink("/proc/self/exe", exe, sizeof exe - 1);
  if (len <= 0) return r;
  exe[len] = '\0';
  // A clean gtest environment for the child (no XML output or sharding inherited from ctest).
  // Passive waiting keeps a 2-thread child fast on a loaded machine (spinning threads starve each other
  // when cores are oversubscribed); it changes nothing in what is computed.
  const std::string cmd = "env -u GTEST_OUTPUT -u GTEST_SHARD_INDEX -u GTEST_TOTAL_SHARDS OMP_NUM_THREADS=" +
                          std::to_string(threads) +
                          " OMP_PROC_BIND=false OMP_WAIT_POLICY=passive TRIAXDEM_HASH_CHILD=1 '" + std::string(exe) +
                          "' --gtest_filter=Determinism." + helper + " 2>&1";
  FILE* f = popen(cmd.c_str(), "r");
  if (f == nullptr) return r;
  char line[1024];
  while (std::fgets(line, sizeof line, f) != nullptr) {
    r.output += line;
    int t;
    unsigned long long h;
    long tc, sl, ro, rb;
    if (std::sscanf(line, "TRIAXDEM_HASH threads=%d hash=%llx touching=%ld sliding=%ld rolling=%ld rebuilds=%ld", &t,
                    &h, &tc, &sl, &ro, &rb) == 6) {
      r.found = true;
      r.threads = t;
      r.hash = h;
      r.touching = tc;
      r.sliding = sl;
      r.rolling = ro;
      r.rebuilds = rb;
    }
  }
  r.status = pclose(f);
  return r;
}

}  // namespace

// Helper run in the child processes: a dense stack of 2,000 balls (jittered cubic lattice, many
// overlapping neighbours) with random velocities and spins, under gravity in a box of six plane walls, friction, rolling resistance and local
// damping on, 1,000 steps (several rebuilds; contacts slide and roll, so history matters). Prints a hash
// of x, v, w in gid order and of the wall forces.
TEST(Determinism, HashChild) {
  if (!child_mode()) GTEST_SKIP() << "helper of Determinism.SameBitsForOneAndTwoThreads (TRIAXDEM_HASH_CHILD=1)";
  const int nx = 10, ny = 10, nz = 20;
  const double a = 2.0e-3;
  std::mt19937_64 rng(31337);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<BallSpec> balls;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        BallSpec b;
        b.radius = (0.98 + 0.04 * u(rng)) * 1e-3;  // neighbours overlap by up to ~5% or have small gaps
        b.x = Vec3((i + 0.5) * a + 2e-5 * (u(rng) - 0.5), (j + 0.5) * a + 2e-5 * (u(rng) - 0.5),
                   (k + 0.5) * a + 2e-5 * (u(rng) - 0.5));
        b.v = Vec3(0.4 * (u(rng) - 0.5), 0.4 * (u(rng) - 0.5), 0.4 * (u(rng) - 0.5));
        b.w = Vec3(400 * (u(rng) - 0.5), 400 * (u(rng) - 0.5), 400 * (u(rng) - 0.5));
        b.material = (i + j + k) % 2;
        balls.push_back(b);
      }
  const double hi[3] = {nx * a, ny * a, nz * a};
  std::vector<WallSpec> walls;
  for (int d = 0; d < 3; ++d)
    for (int side = 0; side < 2; ++side) {
      WallSpec w;
      double p[3] = {0, 0, 0}, n[3] = {0, 0, 0};
      p[d] = side == 0 ? 0 : hi[d];
      n[d] = side == 0 ? 1 : -1;
      w.point = Vec3(p[0], p[1], p[2]);
      w.normal = Vec3(n[0], n[1], n[2]);
      w.material = side;
      walls.push_back(w);
    }
  std::vector<ContactParams> table(4);
  for (int m = 0; m < 4; ++m) {
    table[m].emod = 1e8;
    table[m].kratio = 1.5;
    table[m].mu_s = 0.3 + 0.1 * m;
    table[m].mu_r = 0.05 + 0.05 * m;
    table[m].beta_n = 0.05;
  }
  SimParams prm;
  prm.skin = 0.05e-3;
  prm.integ.alpha = 0.3;
  prm.integ.gravity = Vec3(0, 0, -9.81);
  Simulation sim(make_particles(balls), make_walls(walls), FacetMesh(), table, 2, prm);
  sim.set_dt(0.3 * sim.critical_dt());
  sim.run(1000);

  Fnv1a h;
  const HostParticles hp = to_host_by_gid(sim.particles());
  for (std::size_t i = 0; i < hp.x.size(); ++i) {
    h.add(hp.x[i]);
    h.add(hp.v[i]);
    h.add(hp.w[i]);
  }
  for (const Vec3& f : sim.wall_forces()) h.add(f);
  long touching = 0, sliding = 0, rolling = 0;
  for (const ContactList* c : {&sim.ball_contacts(), &sim.wall_contacts()}) {
    auto fl = Kokkos::create_mirror_view_and_copy(HostSpace(), c->flags);
    auto fn = Kokkos::create_mirror_view_and_copy(HostSpace(), c->fn);
    for (int k = 0; k < c->n; ++k) {
      if (fn(k) <= 0) continue;
      ++touching;
      sliding += (fl(k) & kSliding) ? 1 : 0;
      rolling += (fl(k) & kRolling) ? 1 : 0;
    }
  }
  std::printf("TRIAXDEM_HASH threads=%d hash=%016llx touching=%ld sliding=%ld rolling=%ld rebuilds=%ld\n",
              static_cast<int>(ExecSpace().concurrency()), static_cast<unsigned long long>(h.h), touching, sliding,
              rolling, sim.times().rebuilds);
  std::fflush(stdout);
}

// The children really ran with the thread counts asked for. A GPU has no thread count to set: there the two
// children are two runs of the same device, and their hashes say whether it repeats itself.
namespace {
void expect_thread_counts(const ChildReport& one, const ChildReport& two) {
  if (!Kokkos::SpaceAccessibility<HostSpace, MemSpace>::accessible) return;
  EXPECT_EQ(one.threads, 1);
  EXPECT_EQ(two.threads, 2);
}
}  // namespace

// The same run with 1 and with 2 OpenMP threads must end in bit-identical states: contact lists are
// sorted by key, forces gathered per particle in a fixed order, reductions summed in fixed blocks.
TEST(Determinism, SameBitsForOneAndTwoThreads) {
  if (child_mode()) GTEST_SKIP() << "inside a child run";
  const ChildReport one = run_child(1);
  const ChildReport two = run_child(2);
  ASSERT_TRUE(one.found) << "child with 1 thread printed no hash (status " << one.status << "):\n" << one.output;
  ASSERT_TRUE(two.found) << "child with 2 threads printed no hash (status " << two.status << "):\n" << two.output;
  EXPECT_EQ(one.status, 0) << one.output;
  EXPECT_EQ(two.status, 0) << two.output;
  expect_thread_counts(one, two);
  // The run exercised what could break determinism: many contacts, sliding and rolling history,
  // rebuilds (re-sorting, remapping).
  EXPECT_GT(one.touching, 1000);
  EXPECT_GT(one.sliding, 0);
  EXPECT_GT(one.rolling, 0);
  EXPECT_GT(one.rebuilds, 2);
  EXPECT_EQ(one.touching, two.touching);
  EXPECT_EQ(one.sliding, two.sliding);
  EXPECT_EQ(one.rolling, two.rolling);
  EXPECT_EQ(one.rebuilds, two.rebuilds);
  EXPECT_EQ(one.hash, two.hash) << std::hex << "1 thread: " << one.hash << ", 2 threads: " << two.hash;
}

// Helper run in the child processes: the whole membrane triaxial job on the tiny specimen (packing, layered
// compaction, consolidation inside the membrane, shear to 2%, micro measures at every record). Prints a hash of
// every record (platen and membrane stresses, the membrane's enclosed volume, energies) and micro row, with the
// record count and the time steps in the places of the contact counts.
TEST(Determinism, TriaxialHashChild) {
  if (!child_mode()) GTEST_SKIP() << "helper of Determinism.TriaxialJobSameBitsForOneAndTwoThreads";
  Config c = test::tiny_triaxial_config(0.3, 0.02);
  c.triaxial.axial_strain_end = 0.02;
  const TriaxialResult r = run_triaxial(c, build_specimen(c, false), nullptr, false);
  Fnv1a h;
  for (const TriaxialRecord& x : r.records) h.add(&x, sizeof x);
  std::vector<double> micro;
  for (const MicroRow& m : r.micro) append_micro_state(m, micro);
  h.add(micro.data(), micro.size() * sizeof(double));
  h.add(&r.void_ratio_consolidated, sizeof r.void_ratio_consolidated);
  std::printf("TRIAXDEM_HASH threads=%d hash=%016llx touching=%ld sliding=%ld rolling=0 rebuilds=%ld\n",
              static_cast<int>(ExecSpace().concurrency()), static_cast<unsigned long long>(h.h),
              static_cast<long>(r.records.size()), static_cast<long>(micro.size()), r.steps);
  std::fflush(stdout);
}

// The membrane (its node forces, servo and enclosed volume) and the whole job around it give the same bits with
// 1 and 2 threads: the two children's hashes are compared with each other.
TEST(Determinism, TriaxialJobSameBitsForOneAndTwoThreads) {
  if (child_mode()) GTEST_SKIP() << "inside a child run";
  const ChildReport one = run_child(1, "TriaxialHashChild");
  const ChildReport two = run_child(2, "TriaxialHashChild");
  ASSERT_TRUE(one.found) << "child with 1 thread printed no hash (status " << one.status << "):\n" << one.output;
  ASSERT_TRUE(two.found) << "child with 2 threads printed no hash (status " << two.status << "):\n" << two.output;
  expect_thread_counts(one, two);
  EXPECT_GT(one.touching, 3) << "records: the shear ran";
  EXPECT_GT(one.sliding, 0) << "micro rows were measured";
  EXPECT_EQ(one.touching, two.touching);
  EXPECT_EQ(one.rebuilds, two.rebuilds) << "time steps";
  EXPECT_EQ(one.hash, two.hash) << std::hex << "1 thread: " << one.hash << ", 2 threads: " << two.hash;
}

// A run's bits do not depend on when its neighbour lists were rebuilt, so a batch may rebuild all its cells when one
// is due: the sums over particles go in gid order and those over contacts per owner in key order, past the open
// candidates the skin adds (contact_sums.hpp, Leapfrog), and positions are wrapped into a periodic cell at every step,
// not at a rebuild (step_wrap). Each test runs the same job with the default skin (0.2 mean diameters) and a quarter
// of it, and fails if either did not rebuild several times as often, or if any bit of what they give differs.
namespace {

long rebuilds(const std::vector<StageTiming>& stages) {
  long n = 0;
  for (const StageTiming& t : stages) n += t.parts.rebuilds;
  return n;
}

PeriodicTriaxialResult tiny_periodic_test(Real skin, HostParticles& balls) {
  Config cfg = test::tiny_cell_config();
  cfg.solver.skin = skin;
  auto sim = make_periodic_simulation(make_packing(cfg), cfg.box.size, cfg.ball.base(), cfg.solver);
  PeriodicTriaxialParams prm = cfg.periodic.triax;
  prm.verbose = false;
  const PeriodicTriaxialResult r = run_periodic_triaxial(*sim, prm);
  balls = to_host_by_gid(sim->particles());
  return r;
}

bool same_bits(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(Vec3)) == 0;
}

}  // namespace

// The tiny periodic test: from a gas through the servoed consolidation and the shear to 1%.
TEST(RebuildTiming, ASmallerSkinGivesAPeriodicTestsBits) {
  HostParticles wide_balls, narrow_balls;
  const PeriodicTriaxialResult wide = tiny_periodic_test(0.2, wide_balls), narrow = tiny_periodic_test(0.05, narrow_balls);
  std::printf("rebuilds: %ld with the skin 0.2 d, %ld with 0.05 d\n", rebuilds(wide.stages), rebuilds(narrow.stages));
  EXPECT_GT(rebuilds(narrow.stages), 2 * rebuilds(wide.stages));
  EXPECT_EQ(narrow.consolidation_steps, wide.consolidation_steps);
  ASSERT_EQ(narrow.series.size(), wide.series.size());
  ASSERT_GT(wide.series.size(), 5u);
  for (std::size_t k = 0; k < wide.series.size(); ++k)
    EXPECT_EQ(std::memcmp(&narrow.series[k], &wide.series[k], sizeof(PeriodicTriaxialRecord)), 0)
        << "record " << k << ": q " << narrow.series[k].q << " vs " << wide.series[k].q;
  EXPECT_TRUE(same_bits(narrow_balls.x, wide_balls.x)) << "positions";
  EXPECT_TRUE(same_bits(narrow_balls.v, wide_balls.v)) << "velocities";
  EXPECT_TRUE(same_bits(narrow_balls.w, wide_balls.w)) << "spins";
}

// The tiny membrane test: layered specimen between platens, consolidation inside the membrane, shear to 1%.
TEST(RebuildTiming, ASmallerSkinGivesAMembraneTestsBits) {
  const auto run = [](Real skin) {
    Config c = test::tiny_triaxial_config(0.3, 0.02);
    c.triaxial.axial_strain_end = 0.01;
    c.solver.skin = skin;
    return run_triaxial(c, build_specimen(c, false), nullptr, false);
  };
  const TriaxialResult wide = run(0.2), narrow = run(0.05);
  std::printf("rebuilds: %ld with the skin 0.2 d, %ld with 0.05 d\n", rebuilds(wide.stages), rebuilds(narrow.stages));
  EXPECT_GT(rebuilds(narrow.stages), 2 * rebuilds(wide.stages));
  EXPECT_EQ(narrow.steps, wide.steps);
  ASSERT_EQ(narrow.records.size(), wide.records.size());
  ASSERT_GT(wide.records.size(), 1u);
  // Every field: the platens', the membrane's and the contacts' stresses (q_net summed over the balls by gid).
  for (std::size_t k = 0; k < wide.records.size(); ++k)
    EXPECT_EQ(std::memcmp(&narrow.records[k], &wide.records[k], sizeof(TriaxialRecord)), 0)
        << "record " << k << ": q " << narrow.records[k].q << " vs " << wide.records[k].q;
}
