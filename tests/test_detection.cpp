/// Contact detection and contact bookkeeping: binned search against an O(N^2) oracle, history carried
/// through a rebuild with the particles in another order, and one contact per physical contact on
/// triangulated surfaces (shared edges and vertices).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <map>
#include <numeric>
#include <random>
#include <vector>

#include "host/engine/builder.hpp"
#include "host/engine/simulation.hpp"
#include "host/util/sync_counts.hpp"
#include "kernels/neighbor/binning.hpp"
#include "kernels/neighbor/contact_detect.hpp"
#include "kernels/neighbor/history_remap.hpp"

using namespace dem;

namespace {

constexpr double kPi = 3.14159265358979323846;

std::vector<std::uint64_t> to_vector(const PairKeyView& k) {
  auto h = Kokkos::create_mirror_view_and_copy(HostSpace(), k);
  return std::vector<std::uint64_t>(h.data(), h.data() + h.extent(0));
}

/// Minimum image written out here (not Domain::min_image) so the oracle shares no code with the search.
Vec3 min_image(const Vec3& d, const Domain& dom) {
  double c[3] = {d.x, d.y, d.z};
  for (int k = 0; k < 3; ++k) {
    if (!dom.periodic[k]) continue;
    const double L = dom.hi[k] - dom.lo[k];
    c[k] -= L * std::round(c[k] / L);
  }
  return Vec3(c[0], c[1], c[2]);
}

/// Distance from x to triangle (a, b, c), written independently of closest_on_triangle: the plane
/// distance when the projection falls inside, else the nearest of the three edges.
double dist_point_segment(const Vec3& x, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  double t = dot(x - a, ab) / norm2(ab);
  t = std::min(1.0, std::max(0.0, t));
  return norm(x - (a + t * ab));
}
double dist_point_triangle(const Vec3& x, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 n = cross(b - a, c - a);
  const Vec3 un = (1.0 / norm(n)) * n;
  const double h = dot(x - a, un);
  const Vec3 p = x - h * un;
  const bool inside = dot(cross(b - a, p - a), n) >= 0 && dot(cross(c - b, p - b), n) >= 0 &&
                      dot(cross(a - c, p - c), n) >= 0;
  if (inside) return std::fabs(h);
  return std::min({dist_point_segment(x, a, b), dist_point_segment(x, b, c), dist_point_segment(x, c, a)});
}

struct Packing {
  std::vector<BallSpec> balls;
  std::vector<WallSpec> walls;
  std::vector<double> nodes;
  std::vector<int> tris;
  Domain dom;
  double skin = 0;
};

/// Random (overlapping) balls, radii 0.8-1.2 mm, in an L-box; plane walls on the non-periodic faces.
/// Periodic axes get coordinates beyond the box too, which binning must wrap.
Packing random_packing(int n, double L, bool periodic_xy, bool periodic_z, bool with_mesh, unsigned seed) {
  Packing pk;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  const bool per[3] = {periodic_xy, periodic_xy, periodic_z};
  for (int d = 0; d < 3; ++d) {
    pk.dom.lo[d] = 0;
    pk.dom.hi[d] = L;
    pk.dom.periodic[d] = per[d];
  }
  pk.skin = 0.2e-3;
  for (int i = 0; i < n; ++i) {
    BallSpec b;
    b.radius = (0.8 + 0.4 * u(rng)) * 1e-3;
    double c[3];
    for (int d = 0; d < 3; ++d) c[d] = per[d] ? L * (2 * u(rng) - 0.5) : L * u(rng);
    b.x = Vec3(c[0], c[1], c[2]);
    pk.balls.push_back(b);
  }
  for (int d = 0; d < 3; ++d) {
    if (per[d]) continue;
    for (int side = 0; side < 2; ++side) {
      WallSpec w;
      w.kind = kPlane;
      double p[3] = {0, 0, 0}, nr[3] = {0, 0, 0};
      p[d] = side == 0 ? 0 : L;
      nr[d] = side == 0 ? 1 : -1;
      w.point = Vec3(p[0], p[1], p[2]);
      w.normal = Vec3(nr[0], nr[1], nr[2]);
      pk.walls.push_back(w);
    }
  }
  if (with_mesh) {
    // A bumpy triangulated sheet crossing the box obliquely: 7 x 7 nodes, 72 triangles.
    const int m = 7;
    for (int j = 0; j < m; ++j)
      for (int i = 0; i < m; ++i) {
        const double x = L * i / (m - 1), y = L * j / (m - 1);
        pk.nodes.insert(pk.nodes.end(), {x, y, 0.3 * L + 0.35 * x - 0.1 * y + 0.4e-3 * (u(rng) - 0.5)});
      }
    for (int j = 0; j + 1 < m; ++j)
      for (int i = 0; i + 1 < m; ++i) {
        const int a = j * m + i, b = a + 1, c = a + m + 1, d = a + m;
        pk.tris.insert(pk.tris.end(), {a, b, c, a, c, d});
      }
  }
  return pk;
}

void check_against_oracle(const Packing& pk) {
  Particles p = make_particles(pk.balls);
  const WallSet walls = make_walls(pk.walls);
  const FacetMesh mesh = pk.tris.empty() ? FacetMesh() : make_mesh(pk.nodes, pk.tris, 0);
  double rmax = 0;
  for (const BallSpec& b : pk.balls) rmax = std::max(rmax, b.radius);
  CellList cells;
  bin_particles(p, pk.dom, 2 * rmax + pk.skin, pk.skin, cells);  // the cut-off Simulation uses
  const std::vector<std::uint64_t> pairs = to_vector(detect_pairs(p, cells));
  FacetBins fb;
  if (mesh.ntri > 0) fb = bin_facets(mesh, cells.grid, rmax + pk.skin, fb);
  const std::vector<std::uint64_t> wpairs = to_vector(detect_wall_pairs(p, walls, mesh, fb, cells, pk.skin));

  // Oracle, from the binned (wrapped) positions by gid.
  const HostParticles h = to_host_by_gid(p);
  const int n = static_cast<int>(pk.balls.size());
  std::vector<std::uint64_t> bf, bfw;
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j) {
      const double reach = pk.balls[i].radius + pk.balls[j].radius + pk.skin;
      if (norm(min_image(h.x[j] - h.x[i], pk.dom)) < reach) bf.push_back((std::uint64_t(i) << 32) | std::uint64_t(j));
    }
  for (int w = 0; w < static_cast<int>(pk.walls.size()); ++w)
    for (int i = 0; i < n; ++i) {
      const Vec3 nr = (1.0 / norm(pk.walls[w].normal)) * pk.walls[w].normal;
      if (dot(h.x[i] - pk.walls[w].point, nr) < pk.balls[i].radius + pk.skin)
        bfw.push_back((std::uint64_t(w) << 32) | std::uint64_t(i));
    }
  const int nt = static_cast<int>(pk.tris.size() / 3);
  auto node = [&](int k) { return Vec3(pk.nodes[3 * k], pk.nodes[3 * k + 1], pk.nodes[3 * k + 2]); };
  for (int t = 0; t < nt; ++t)
    for (int i = 0; i < n; ++i) {
      const double d = dist_point_triangle(h.x[i], node(pk.tris[3 * t]), node(pk.tris[3 * t + 1]), node(pk.tris[3 * t + 2]));
      if (d < pk.balls[i].radius + pk.skin)
        bfw.push_back((std::uint64_t(pk.walls.size() + t) << 32) | std::uint64_t(i));
    }
  std::sort(bf.begin(), bf.end());
  std::sort(bfw.begin(), bfw.end());
  ASSERT_GT(bf.size(), static_cast<std::size_t>(n)) << "test set-up: the packing should be dense";
  if (!pk.walls.empty()) {
    ASSERT_GT(bfw.size(), 20u);
  }
  // Returned sorted and without duplicates.
  EXPECT_TRUE(std::is_sorted(pairs.begin(), pairs.end()));
  EXPECT_TRUE(std::adjacent_find(pairs.begin(), pairs.end()) == pairs.end());
  EXPECT_TRUE(std::adjacent_find(wpairs.begin(), wpairs.end()) == wpairs.end());
  // Same sets. Exact comparisons of distances with the cut-off could differ in the last ulp between
  // the two computations; a random packing puts no pair within 1e-16 of its cut-off.
  std::vector<std::uint64_t> missing, extra;
  std::set_difference(bf.begin(), bf.end(), pairs.begin(), pairs.end(), std::back_inserter(missing));
  std::set_difference(pairs.begin(), pairs.end(), bf.begin(), bf.end(), std::back_inserter(extra));
  EXPECT_TRUE(missing.empty()) << missing.size() << " ball-ball pairs missed, first " << std::hex
                               << (missing.empty() ? 0 : missing[0]);
  EXPECT_TRUE(extra.empty()) << extra.size() << " ball-ball pairs beyond the cut-off";
  missing.clear();
  extra.clear();
  std::vector<std::uint64_t> ws = wpairs;
  std::sort(ws.begin(), ws.end());
  std::set_difference(bfw.begin(), bfw.end(), ws.begin(), ws.end(), std::back_inserter(missing));
  std::set_difference(ws.begin(), ws.end(), bfw.begin(), bfw.end(), std::back_inserter(extra));
  EXPECT_TRUE(missing.empty()) << missing.size() << " ball-wall pairs missed, first " << std::hex
                               << (missing.empty() ? 0 : missing[0]);
  EXPECT_TRUE(extra.empty()) << extra.size() << " ball-wall pairs beyond the cut-off";
  EXPECT_EQ(ws, wpairs) << "ball-wall keys not sorted";
}

}  // namespace

TEST(Detection, BinnedEqualsBruteForceInWalledBox) {
  check_against_oracle(random_packing(500, 19e-3, false, false, true, 11));
}

TEST(Detection, BinnedEqualsBruteForcePeriodic) {
  // Periodic in x and y (coordinates scattered over two box lengths), plane walls top and bottom.
  check_against_oracle(random_packing(500, 19e-3, true, false, false, 12));
  // Fully periodic with exactly three cells per axis (the smallest allowed): the -1 and +1 neighbour
  // cells wrap onto each other's side, and every pair must still be found once.
  const double L = 3 * (2 * 1.2e-3 + 0.2e-3) * 1.01;
  Packing pk = random_packing(60, L, true, true, false, 13);
  double rmax = 0;
  for (const BallSpec& b : pk.balls) rmax = std::max(rmax, b.radius);
  ASSERT_EQ(static_cast<int>(std::floor(L / (2 * rmax + pk.skin))), 3);
  check_against_oracle(pk);
}

// ---------------------------------------------------------------------------------------------------
// History survives a rebuild with the particles in another order: history is keyed by global ids,
// so remapping it onto a list built from permuted particles must give every surviving contact
// bit-identical shear force, rolling moment and flags, and resolve local indices to the right balls.
/// A batch's specimen binned and searched beside others, in one pass: what it gets alone, to the bit.
struct Binned {
  std::vector<std::uint32_t> order;  ///< gids in the binned order
  std::vector<double> x;             ///< positions in that order
  std::vector<std::uint64_t> keys;
};

/// Specimen s of the batch's particles and keys (gids less `first`), or the whole of a simulation of one.
Binned binned(const Particles& p, const std::vector<std::uint64_t>& keys, int first, int count) {
  auto g = Kokkos::create_mirror_view_and_copy(HostSpace(), p.gid);
  auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), p.x);
  Binned b;
  for (int i = first; i < first + count; ++i) {
    b.order.push_back(g(i) - static_cast<std::uint32_t>(first));
    for (int d = 0; d < 3; ++d) b.x.push_back(x(i, d));
  }
  for (std::uint64_t k : keys)
    if (key_hi(k) >= static_cast<std::uint32_t>(first) && key_hi(k) < static_cast<std::uint32_t>(first + count))
      b.keys.push_back(pair_key(key_hi(k) - first, key_lo(k) - first));
  return b;
}

double max_radius(const std::vector<BallSpec>& balls) {
  double r = 0;
  for (const BallSpec& b : balls) r = std::max(r, b.radius);
  return r;
}

/// Moves every ball by up to `step` (m) along each axis, by its specimen and its gid less the specimen's `first`:
/// the same way in the batch and alone (`as`: the specimen a simulation of one holds).
void jiggle(Particles& p, double step, unsigned seed, const std::vector<int>& first, int as = -1) {
  auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), p.x);
  auto g = Kokkos::create_mirror_view_and_copy(HostSpace(), p.gid);
  auto spec = Kokkos::create_mirror_view_and_copy(HostSpace(), p.specimen);
  for (int i = 0; i < p.n; ++i) {
    const int sp = as >= 0 ? as : spec(i);
    std::mt19937_64 rng(seed + 7919u * (g(i) - (as >= 0 ? 0u : static_cast<unsigned>(first[sp]))) + 104729u * sp);
    std::uniform_real_distribution<double> u(-step, step);
    for (int d = 0; d < 3; ++d) x(i, d) += u(rng);
  }
  Kokkos::deep_copy(p.x, x);
}

TEST(Detection, ABatchBinsAndSearchesEachSpecimenAsItWouldAlone) {
  // Three specimens of other sizes and boxes (the third open along z, so its grid is sized to its balls).
  const std::vector<Packing> packs = {random_packing(300, 12e-3, true, true, false, 3),
                                      random_packing(200, 10e-3, true, true, false, 4),
                                      random_packing(250, 11e-3, true, false, false, 5)};
  std::vector<BallSpec> all;
  std::vector<int> first;
  for (std::size_t s = 0; s < packs.size(); ++s) {
    first.push_back(static_cast<int>(all.size()));
    for (BallSpec b : packs[s].balls) {
      b.specimen = static_cast<int>(s);
      all.push_back(b);
    }
  }
  Particles batch = make_particles(all);  // gid = place in `all`: each specimen's gids start at its first ball
  std::vector<Particles> alone;
  std::vector<SpecimenBin> bins;
  for (std::size_t s = 0; s < packs.size(); ++s) {
    const Packing& pk = packs[s];
    alone.push_back(make_particles(pk.balls));
    bins.push_back({first[s], static_cast<int>(pk.balls.size()), pk.dom, 2 * max_radius(pk.balls) + pk.skin, pk.skin,
                    true});
  }
  // Twice: all rebuilt; then the balls moved, and the second specimen kept as it was.
  std::vector<std::vector<std::uint64_t>> kept_alone(packs.size());
  PairKeyView batch_keys;
  for (int round = 0; round < 2; ++round) {
    if (round == 1) {
      jiggle(batch, 0.1e-3, 17u, first);
      for (std::size_t s = 0; s < packs.size(); ++s) jiggle(alone[s], 0.1e-3, 17u, first, static_cast<int>(s));
      bins[1].rebuild = false;
    }
    CellList cells;
    PairKeyView kept;
    Index2View kept_own;
    if (round == 1) {
      ContactList old(static_cast<int>(batch_keys.extent(0)));
      Kokkos::deep_copy(old.key, batch_keys);
      kept = batch_keys;
      kept_own = owner_ranges(batch, old);
    }
    bin_specimens(batch, bins, cells);
    batch_keys = detect_pairs(batch, cells, kept, kept_own);
    const std::vector<std::uint64_t> keys = to_vector(batch_keys);
    for (std::size_t s = 0; s < packs.size(); ++s) {
      const Packing& pk = packs[s];
      const int n = static_cast<int>(pk.balls.size());
      Binned want;
      if (bins[s].rebuild) {
        CellList own;
        bin_particles(alone[s], pk.dom, bins[s].cell_min, pk.skin, own);
        want = binned(alone[s], to_vector(detect_pairs(alone[s], own)), 0, n);
        if (round == 0) kept_alone[s] = want.keys;
      } else {
        // Not rebuilt: its balls (moved) stay where they were, and its contacts are the list before.
        want = binned(alone[s], kept_alone[s], 0, n);
      }
      const Binned got = binned(batch, keys, first[s], n);
      EXPECT_EQ(got.order, want.order) << "specimen " << s << ", round " << round;
      EXPECT_TRUE(std::memcmp(got.x.data(), want.x.data(), got.x.size() * sizeof(double)) == 0)
          << "specimen " << s << ", round " << round;
      EXPECT_EQ(got.keys, want.keys) << "specimen " << s << ", round " << round;
      EXPECT_GT(got.keys.size(), 100u) << "specimen " << s;
    }
  }
}

TEST(Detection, HistoryUnchangedByPermutedRebuild) {
  // A jittered cubic stack of 5 x 5 x 5 balls, spacing a = 1.96 mm, radii 0.96-1.00 mm: neighbours
  // overlap by up to 4% of a radius or have small gaps. Periodic in x and y, plane walls below and
  // above. A shear velocity profile v_x ~ z, noise and random spins make the contacts slide and roll.
  const int nl = 5;
  const double a = 1.96e-3, L = nl * a;
  std::mt19937_64 rng(77);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<BallSpec> balls;
  for (int k = 0; k < nl; ++k)
    for (int j = 0; j < nl; ++j)
      for (int i = 0; i < nl; ++i) {
        BallSpec b;
        b.radius = (0.96 + 0.04 * u(rng)) * 1e-3;
        b.x = Vec3((i + 0.5) * a + 1e-5 * (u(rng) - 0.5), (j + 0.5) * a + 1e-5 * (u(rng) - 0.5),
                   (k + 0.5) * a + 1e-5 * (u(rng) - 0.5));
        b.v = Vec3(0.5 * (b.x.z / L - 0.5) + 0.1 * (u(rng) - 0.5), 0.1 * (u(rng) - 0.5), 0.1 * (u(rng) - 0.5));
        b.w = Vec3(200 * (u(rng) - 0.5), 200 * (u(rng) - 0.5), 200 * (u(rng) - 0.5));
        balls.push_back(b);
      }
  const double R = 1e-3;
  std::vector<WallSpec> walls(2);
  walls[0].normal = Vec3(0, 0, 1);
  walls[1].point = Vec3(0, 0, L);
  walls[1].normal = Vec3(0, 0, -1);
  SimParams prm;
  prm.skin = 0.1 * R;
  prm.integ.alpha = 0.0;
  prm.integ.gravity = Vec3(0, 0, -9.81);
  for (int d = 0; d < 2; ++d) {
    prm.domain.hi[d] = L;
    prm.domain.periodic[d] = true;
  }
  prm.domain.hi[2] = L;
  ContactParams cp;
  cp.mu_s = 0.3;
  cp.mu_r = 0.1;
  Simulation sim(make_particles(balls), make_walls(walls), FacetMesh(), {cp}, 1, prm);
  sim.set_dt(0.3 * sim.critical_dt());
  sim.run(400);

  struct Hist {
    Vec3 fs, mr;
    int flags;
  };
  auto snapshot = [](const ContactList& c) {
    std::map<std::uint64_t, Hist> out;
    auto key = Kokkos::create_mirror_view_and_copy(HostSpace(), c.key);
    auto fs = Kokkos::create_mirror_view_and_copy(HostSpace(), c.fs);
    auto mr = Kokkos::create_mirror_view_and_copy(HostSpace(), c.mr);
    auto fl = Kokkos::create_mirror_view_and_copy(HostSpace(), c.flags);
    for (int k = 0; k < c.n; ++k) out[key(k)] = Hist{load(fs, k), load(mr, k), fl(k)};
    return out;
  };
  const std::map<std::uint64_t, Hist> old_b = snapshot(sim.ball_contacts());
  const std::map<std::uint64_t, Hist> old_w = snapshot(sim.wall_contacts());

  // The particles in a random order (a shallow copy: permute() allocates new Views, sim is untouched).
  Particles q = sim.particles();
  std::vector<int> perm(q.n);
  std::iota(perm.begin(), perm.end(), 0);
  std::shuffle(perm.begin(), perm.end(), rng);
  IndexView dperm("perm", q.n);
  auto hperm = Kokkos::create_mirror_view(dperm);
  for (int k = 0; k < q.n; ++k) hperm(k) = perm[k];
  Kokkos::deep_copy(dperm, hperm);
  q.permute(dperm);
  // New candidate keys from a binned copy (binning re-sorts, which is why the remap below is given
  // the randomly ordered particles q, not this copy).
  Particles r = q;
  CellList cells;
  double rmax = 0;
  for (const BallSpec& b : balls) rmax = std::max(rmax, b.radius);
  // A wider skin than the simulation's brings in candidates the old lists lack: they must start empty.
  const double skin2 = 10 * prm.skin;  // reaches the lattice diagonals (2.77 mm apart)
  bin_particles(r, prm.domain, 2 * rmax + skin2, skin2, cells);
  const PairKeyView bkeys = detect_pairs(r, cells);
  const WallSet ws = make_walls(walls);
  const PairKeyView wkeys = detect_wall_pairs(r, ws, FacetMesh(), FacetBins(), cells, skin2);
  const IndexView g2l = gid_to_local(q);
  const ContactList nb = remap_history(bkeys, sim.ball_contacts(), g2l, true);
  const ContactList nw = remap_history(wkeys, sim.wall_contacts(), g2l, false);

  auto gid = Kokkos::create_mirror_view_and_copy(HostSpace(), q.gid);
  long common = 0, loaded = 0, fresh = 0;
  for (int list = 0; list < 2; ++list) {
    const ContactList& c = list == 0 ? nb : nw;
    const std::map<std::uint64_t, Hist>& old = list == 0 ? old_b : old_w;
    auto key = Kokkos::create_mirror_view_and_copy(HostSpace(), c.key);
    auto ci = Kokkos::create_mirror_view_and_copy(HostSpace(), c.i);
    auto cj = Kokkos::create_mirror_view_and_copy(HostSpace(), c.j);
    auto fs = Kokkos::create_mirror_view_and_copy(HostSpace(), c.fs);
    auto mr = Kokkos::create_mirror_view_and_copy(HostSpace(), c.mr);
    auto fl = Kokkos::create_mirror_view_and_copy(HostSpace(), c.flags);
    for (int k = 0; k < c.n; ++k) {
      const std::uint64_t kk = key(k);
      // Local indices point at the right balls of the permuted order.
      if (list == 0) {
        EXPECT_EQ(gid(ci(k)), key_hi(kk));
        EXPECT_EQ(gid(cj(k)), key_lo(kk));
      } else {
        EXPECT_EQ(gid(ci(k)), key_lo(kk));
        EXPECT_EQ(static_cast<std::uint32_t>(cj(k)), key_hi(kk));
      }
      const auto it = old.find(kk);
      if (it == old.end()) {
        ++fresh;  // a new candidate starts from nothing
        EXPECT_EQ(norm(load(fs, k)), 0.0);
        EXPECT_EQ(norm(load(mr, k)), 0.0);
        EXPECT_EQ(fl(k), 0);
        continue;
      }
      ++common;
      if (norm(it->second.fs) > 0 && norm(it->second.mr) > 0) ++loaded;
      for (int d = 0; d < 3; ++d) {  // bit-identical: a copy, not a recomputation
        EXPECT_EQ(fs(k, d), it->second.fs[d]) << std::hex << kk;
        EXPECT_EQ(mr(k, d), it->second.mr[d]) << std::hex << kk;
      }
      EXPECT_EQ(fl(k), it->second.flags);
    }
  }
  // The test is only meaningful when many surviving contacts carry non-zero history.
  EXPECT_GT(loaded, 50) << "common " << common << ", fresh " << fresh;
  EXPECT_GT(fresh, 0);
  // Every old touching contact is still a candidate (nothing moved), so nothing was lost.
  long old_touching = 0;
  for (const auto* old : {&old_b, &old_w})
    for (const auto& kv : *old) old_touching += (kv.second.flags & kTouching) ? 1 : 0;
  EXPECT_GE(common, old_touching);
}

// ---------------------------------------------------------------------------------------------------
// Facets: one contact per physical contact. A ball pressed by d into a flat triangulated sheet must
// get exactly one contact wherever it touches (inside a face, on an edge shared by two triangles, on
// a vertex shared by 6 or 3 triangles), with the sheet's normal and force kn d, kn = pi R E* (ball-facet
// stiffness, L = R). A ball in a concave fold touches two faces and gets two contacts; a ball on a
// convex ridge touches one edge and gets one.
namespace {

struct FacetResult {
  int touching = 0;
  std::vector<Vec3> normals, forces;
  std::vector<double> fn;
  Vec3 wall_total;
};

FacetResult press_ball(const std::vector<double>& nodes, const std::vector<int>& tris, const Vec3& x, double R,
                       double emod) {
  std::vector<BallSpec> b(1);
  b[0].x = x;
  b[0].radius = R;
  SimParams prm;
  prm.skin = 0.1 * R;
  prm.integ.alpha = 0;
  prm.integ.gravity = Vec3();
  ContactParams cp;
  cp.emod = emod;
  Simulation sim(make_particles(b), make_walls({}), make_mesh(nodes, tris, 0), {cp}, 1, prm);
  sim.set_dt(0.1 * sim.critical_dt());
  sim.step();  // forces at x
  const ContactList& c = sim.wall_contacts();
  auto fn = Kokkos::create_mirror_view_and_copy(HostSpace(), c.fn);
  auto fc = Kokkos::create_mirror_view_and_copy(HostSpace(), c.fc);
  FacetResult out;
  for (int k = 0; k < c.n; ++k) {
    if (fn(k) <= 0) continue;
    ++out.touching;
    // The ball is at rest: no shear force, so the contact force on it is -Fn n, n the unit normal from
    // the ball to the facet.
    const Vec3 f = load(fc, k);
    out.normals.push_back(-(1.0 / norm(f)) * f);
    out.forces.push_back(load(fc, k));
    out.fn.push_back(fn(k));
  }
  for (const Vec3& f : sim.wall_forces()) out.wall_total += f;
  return out;
}

}  // namespace

TEST(Detection, FlatFacetSheetGivesOneContactAtFacesEdgesAndVertices) {
  const double s = 1.5e-3, R = 1e-3, E = 1e8, d = 1e-5;
  // 3 x 3 nodes at x, y in {-s, 0, s}; each quad split along its (i,j)-(i+1,j+1) diagonal: the centre
  // node is shared by 6 triangles, the mid-side nodes by 3.
  std::vector<double> nodes;
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) nodes.insert(nodes.end(), {(i - 1) * s, (j - 1) * s, 0.0});
  std::vector<int> tris;
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) {
      const int a = 3 * j + i, b = a + 1, c = a + 4, dd = a + 3;
      tris.insert(tris.end(), {a, b, c, a, c, dd});
    }
  const double kn = kPi * R * E;
  const double h = R - d;
  struct Case {
    const char* where;
    double x, y;
  };
  const Case cases[] = {
      {"face (centroid of a triangle)", -s / 3, -2 * s / 3},
      {"face (off-centre)", 0.37 * s, 0.81 * s},
      {"quad diagonal, shared by 2 triangles", -s / 2, -s / 2},
      {"quad diagonal, off its midpoint", 0.3 * s, 0.3 * s},
      {"edge between quads, shared by 2 triangles", 0.0, -s / 2},
      {"edge between quads (other axis)", 0.62 * s, 0.0},
      {"vertex shared by 6 triangles", 0.0, 0.0},
      {"vertex on the border shared by 3 triangles", s, 0.0},
      {"vertex on the border shared by 3 triangles (other)", 0.0, -s},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.where);
    const FacetResult r = press_ball(nodes, tris, Vec3(c.x, c.y, h), R, E);
    ASSERT_EQ(r.touching, 1);
    // Normal from the ball to the sheet, perpendicular to it (1e-12: rounding of closest points).
    // Exactly one of the candidate facets carries the whole force kn d.
    EXPECT_NEAR(r.normals[0].x, 0.0, 1e-12);
    EXPECT_NEAR(r.normals[0].y, 0.0, 1e-12);
    EXPECT_NEAR(r.normals[0].z, -1.0, 1e-12);
    // kn d: the overlap is R - |cp - x| with |cp - x| ~ R, so rounding is ~1e-16 R / d = 1e-13 relative.
    EXPECT_NEAR(r.fn[0], kn * d, 1e-9 * kn * d);
    EXPECT_NEAR(r.forces[0].z, kn * d, 1e-9 * kn * d);
    EXPECT_NEAR(r.wall_total.z, -kn * d, 1e-9 * kn * d);
  }
  // Random points on random features: vertices exactly, points on edges (on the edge up to the
  // rounding of a + t (b - a)), and inside faces. Always one contact, always kn d.
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  auto node = [&](int k) { return Vec3(nodes[3 * k], nodes[3 * k + 1], nodes[3 * k + 2]); };
  for (int trial = 0; trial < 150; ++trial) {
    const int t = static_cast<int>(u(rng) * 8) % 8, kind = trial % 3;
    const Vec3 A = node(tris[3 * t]), B = node(tris[3 * t + 1]), C = node(tris[3 * t + 2]);
    Vec3 p;
    if (kind == 0) p = trial % 2 ? B : C;
    else if (kind == 1) p = A + u(rng) * (B - A);
    else {
      double w1 = u(rng), w2 = u(rng);
      if (w1 + w2 > 1) { w1 = 1 - w1; w2 = 1 - w2; }
      p = A + w1 * (B - A) + w2 * (C - A);
    }
    SCOPED_TRACE("random point " + std::to_string(trial) + " kind " + std::to_string(kind));
    const FacetResult r = press_ball(nodes, tris, Vec3(p.x, p.y, h), R, E);
    ASSERT_EQ(r.touching, 1);
    EXPECT_NEAR(r.normals[0].z, -1.0, 1e-12);
    EXPECT_NEAR(r.fn[0], kn * d, 1e-9 * kn * d);
  }
}

TEST(Detection, ConcaveFoldGivesTwoContactsConvexRidgeOne) {
  const double R = 1e-3, E = 1e8, d = 2e-5, W = 3e-3;
  const double th = 30 * kPi / 180, tn = std::tan(th);
  const double kn = kPi * R * E;
  // Two planes meeting along the y axis, z = sign * |x| tan(th): sign +1 a valley, -1 a ridge.
  // Nodes x in {-W, 0, W}, y in {-W, W}; each side a quad of two triangles.
  auto fold = [&](double sign, std::vector<double>& nodes, std::vector<int>& tris) {
    nodes.clear();
    tris.clear();
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 3; ++i) {
        const double x = (i - 1) * W;
        nodes.insert(nodes.end(), {x, (2 * j - 1) * W, sign * std::fabs(x) * tn});
      }
    for (int i = 0; i < 2; ++i) {
      const int a = i, b = i + 1, c = i + 4, dd = i + 3;
      tris.insert(tris.end(), {a, b, c, a, c, dd});
    }
  };
  std::vector<double> nodes;
  std::vector<int> tris;
  {
    SCOPED_TRACE("concave valley");
    fold(+1, nodes, tris);
    // Centre above the fold line at the height where its distance to each face is R - d.
    const double z0 = (R - d) / std::cos(th);
    const FacetResult r = press_ball(nodes, tris, Vec3(0, 1e-3, z0), R, E);
    ASSERT_EQ(r.touching, 2);
    for (int k = 0; k < 2; ++k) {
      // Each normal is perpendicular to its face: (+-sin th, 0, -cos th).
      EXPECT_NEAR(std::fabs(r.normals[k].x), std::sin(th), 1e-12);
      EXPECT_NEAR(r.normals[k].y, 0.0, 1e-12);
      EXPECT_NEAR(r.normals[k].z, -std::cos(th), 1e-12);
      EXPECT_NEAR(r.fn[k], kn * d, 1e-9 * kn * d);
    }
    EXPECT_LT(r.normals[0].x * r.normals[1].x, 0.0);  // one on each face
    // The two faces push up together with 2 kn d cos(th); sideways they cancel.
    EXPECT_NEAR(r.wall_total.z, -2 * kn * d * std::cos(th), 1e-9 * kn * d);
    EXPECT_NEAR(r.wall_total.x, 0.0, 1e-9 * kn * d);
  }
  {
    SCOPED_TRACE("convex ridge");
    fold(-1, nodes, tris);
    const FacetResult r = press_ball(nodes, tris, Vec3(0, 1e-3, R - d), R, E);
    ASSERT_EQ(r.touching, 1);
    EXPECT_NEAR(r.normals[0].x, 0.0, 1e-12);
    EXPECT_NEAR(r.normals[0].z, -1.0, 1e-12);
    EXPECT_NEAR(r.fn[0], kn * d, 1e-9 * kn * d);
  }
}

namespace {

/// Keys as a rebuild makes them: ball-ball pairs over many gids, then ball-wall keys of three objects, each over
/// thousands of gids (a bin sort over the raw key puts each object's keys in one bin), in a scrambled order.
std::vector<std::uint64_t> scrambled_keys() {
  std::vector<std::uint64_t> k;
  std::mt19937 rng(5);
  std::uniform_int_distribution<std::uint32_t> gid(0, 20000);
  for (int c = 0; c < 30000; ++c) {
    const std::uint32_t a = gid(rng), b = gid(rng);
    if (a != b) k.push_back(pair_key(a, b));
  }
  for (int obj = 0; obj < 3; ++obj)
    for (std::uint32_t g = 0; g < 20000; g += 1 + obj) k.push_back(wall_key(obj, g));
  std::sort(k.begin(), k.end());
  k.erase(std::unique(k.begin(), k.end()), k.end());
  std::shuffle(k.begin(), k.end(), rng);
  return k;
}

}  // namespace

TEST(Detection, KeySortsGiveTheOrderOfStdSort) {
  const std::vector<std::uint64_t> keys = scrambled_keys();
  std::vector<std::uint64_t> want = keys;
  std::sort(want.begin(), want.end());
  KeySortBuffers kept;
  for (const bool bins : {false, true}) {
    PairKeyView d("keys", keys.size());
    auto h = Kokkos::create_mirror_view(d);
    for (std::size_t i = 0; i < keys.size(); ++i) h(i) = keys[i];
    Kokkos::deep_copy(d, h);
    if (bins) bin_sort_keys(d, kept); else sort_keys(d, kept);
    Kokkos::deep_copy(h, d);
    for (std::size_t i = 0; i < keys.size(); ++i)
      ASSERT_EQ(h(i), want[i]) << (bins ? "bin_sort_keys" : "sort_keys") << ", position " << i << " of " << keys.size();
  }
}

// A GPU's rebuild sorts with bin_sort_keys, whose buffers are kept (KeySortBuffers in ListBuffers): a later sort of
// as many keys or fewer allocates nothing and copies nothing (what it may read back: the keys' range, two reductions
// that set the bins, and the scan of the bins' counts, which the counter takes for a read). Kokkos::BinSort
// allocated its counts, offsets, permutation and a copy of the keys at every sort (a GPU rebuild counted 10-13
// allocations, the CPU's 1-5). Counted on the CPU, where the calls are the same.
TEST(Detection, AKeySortAfterTheFirstAllocatesNothing) {
  ASSERT_TRUE(count_syncs()) << "a profiling tool holds Kokkos' callbacks";
  std::vector<std::uint64_t> keys = scrambled_keys();
  KeySortBuffers kept;
  PairKeyView d("keys", keys.size());
  auto h = Kokkos::create_mirror_view(d);
  for (std::size_t i = 0; i < keys.size(); ++i) h(i) = keys[i];
  Kokkos::deep_copy(d, h);
  bin_sort_keys(d, kept);
  std::shuffle(keys.begin(), keys.end(), std::mt19937(7));
  const PairKeyView fewer = Kokkos::subview(d, std::make_pair(std::size_t(0), keys.size() - 100));
  for (std::size_t i = 0; i < fewer.extent(0); ++i) h(i) = keys[i];
  Kokkos::deep_copy(d, h);
  const SyncTally before = sync_tally();
  bin_sort_keys(fewer, kept);
  Kokkos::fence();
  const SyncCounts c = sync_tally()[0] - before[0];
  EXPECT_EQ(c.allocations, 0);
  EXPECT_EQ(c.copies, 0) << "the sorted keys go back in a kernel";
  EXPECT_LE(c.host_results, 3);
  std::vector<std::uint64_t> want(keys.begin(), keys.end() - 100);
  std::sort(want.begin(), want.end());
  Kokkos::deep_copy(h, d);
  for (std::size_t i = 0; i < want.size(); ++i) ASSERT_EQ(h(i), want[i]) << "position " << i;
}
