/// The ball-ball force kernel evaluates kContactLanes contacts side by side (kernels/core/simd.hpp). These tests hold it
/// to what makes that safe: a lane gives the bits of the scalar law (the build fuses no multiply-add, so both round
/// every operation alike), whatever its neighbours in the pack are doing, and the kernel's result for a contact does
/// not depend on which lane or pack it falls in. Comparisons are exact: any difference is a lane mixed up or a
/// masked branch that computes something else, not rounding.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "host/engine/builder.hpp"
#include "host/config/model_keys.hpp"
#include "kernels/contact/contact_force.hpp"
#include "kernels/motion/integrate.hpp"
#include "test_util.hpp"
#include "tree_sum.hpp"

using namespace dem;

namespace {

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }
bool same_bits(const Vec3& a, const Vec3& b) { return same_bits(a.x, b.x) && same_bits(a.y, b.y) && same_bits(a.z, b.z); }

struct LawCase {
  ContactParams p;
  ContactKinematics k;
  ContactHistory h;
};

/// The contact law's extensions as the model's table lists them (host/config/model_keys.hpp), so that a new one
/// is in the lanes' test without a line here.
std::vector<const ModelKey*> law_extensions() {
  std::vector<const ModelKey*> out;
  for (const ModelKey& k : model_keys())
    if (*k.extension && k.field) out.push_back(&k);
  return out;
}

/// A random touching contact: in turn the base law, the dashpot and each extension of the table at the strongest
/// strength the diagnosis tries; every seventh is a wall, every third starts with no history and some have history
/// along n (it must vanish) or loads past the caps. Of each kContactLaws + 1 packs of lanes one is of each law's
/// contacts and one of all laws in turn (ContactLaws runs each and keeps each lane's); a law's needed keys (its
/// constants, model_keys) drawn in their search range, or their allowed range where a calibration does not free them.
LawCase random_case(std::mt19937_64& rng, int t) {
  static const std::vector<const ModelKey*> extensions = law_extensions();
  std::uniform_real_distribution<double> u(-1, 1);
  LawCase c;
  c.p = test::law(1e8, 1.5, 0.3, 0.02);
  const int kind = t % static_cast<int>(extensions.size() + 2);
  if (kind == 1) c.p.beta_n = 0.2;
  if (kind >= 2) {
    const ModelKey& e = *extensions[static_cast<std::size_t>(kind - 2)];
    c.p.*e.field = e.strengths.back();
  }
  Vec3 n(u(rng), u(rng), u(rng));
  c.k.n = (1 / norm(n)) * n;
  c.k.overlap = 1e-6 * (1.01 + u(rng));
  c.k.r1 = 1e-3 * (1 + 0.2 * u(rng));
  c.k.r2 = t % 7 == 0 ? 0 : 1e-3 * (1 + 0.2 * u(rng));
  c.k.m1 = 1e-5;
  c.k.m2 = c.k.r2 > 0 ? 1.2e-5 : 0;
  const int pack = t / kContactLanes, laws = kContactLaws;
  c.p.law = static_cast<ContactLawId>(pack % (laws + 1) < laws ? pack % (laws + 1) : t % laws);
  for (const ModelKey& key : model_keys())
    if (key.required && own_key_of(key, kContactLawNames[c.p.law])) {
      const double a = 0.5 * (1 + u(rng));
      c.p.*key.field = !key.fit ? key.lo + a * (key.hi - key.lo)
                       : key.fit_log ? key.fit_lo * std::pow(key.fit_hi / key.fit_lo, a)
                                     : key.fit_lo + a * (key.fit_hi - key.fit_lo);
    }
  c.k.kn = ContactLaws::stiffness(c.p, c.k.r1, c.k.r2);
  c.k.vrel = Vec3(u(rng), u(rng), u(rng));
  c.k.dtheta = 1e-3 * Vec3(u(rng), u(rng), u(rng));
  c.k.dt = 1e-7;
  const double scale = t % 3 == 0 ? 0 : (t % 3 == 1 ? 1e-4 : 1e-1);  // none, elastic, past the caps
  c.h.fs = scale * Vec3(u(rng), u(rng), u(rng));
  c.h.mr = 1e-3 * scale * Vec3(u(rng), u(rng), u(rng));
  if (t % 11 == 0) c.h.fs = scale * c.k.n;
  c.h.slot[kSlipSlot] = 1e-5 * (1 + u(rng));
  c.h.slot[kTwistSlot] = 1e-3 * scale * u(rng);
  return c;
}

#ifdef TRIAXDEM_HOST_PACKS
TEST(SimdLanes, EachLaneGivesTheScalarLawsBits) {
  std::mt19937_64 rng(2026);
  using T = ContactPack;
  for (int t0 = 0; t0 < 40000; t0 += kContactLanes) {
    LawCase c[kContactLanes];
    for (int k = 0; k < kContactLanes; ++k) c[k] = random_case(rng, t0 + k);
    const auto lanes = [&](auto get) { return from_lanes<T>([&](int k) { return get(c[k]); }); };
    const auto vlanes = [&](auto get) { return vec_of_lanes<T>([&](int k) { return get(c[k]); }); };
    const ContactParamsT<T> P = params_of_lanes<T>([&](int k) -> const ContactParams& { return c[k].p; });
    ContactKinematicsT<T> K;
    K.n = vlanes([](const LawCase& q) { return q.k.n; });
    K.overlap = lanes([](const LawCase& q) { return q.k.overlap; });
    K.kn = lanes([](const LawCase& q) { return q.k.kn; });
    K.r1 = lanes([](const LawCase& q) { return q.k.r1; });
    K.r2 = lanes([](const LawCase& q) { return q.k.r2; });
    K.m1 = lanes([](const LawCase& q) { return q.k.m1; });
    K.m2 = lanes([](const LawCase& q) { return q.k.m2; });
    K.vrel = vlanes([](const LawCase& q) { return q.k.vrel; });
    K.dtheta = vlanes([](const LawCase& q) { return q.k.dtheta; });
    K.dt = c[0].k.dt;
    ContactHistoryT<T> H;
    H.fs = vlanes([](const LawCase& q) { return q.h.fs; });
    H.mr = vlanes([](const LawCase& q) { return q.h.mr; });
    for (int s = 0; s < kHistorySlots; ++s) H.slot[s] = lanes([s](const LawCase& q) { return q.h.slot[s]; });
    const ContactOutputT<T> out = ContactLaws::eval(P, K, H);
    for (int k = 0; k < kContactLanes; ++k) {
      ContactHistory h = c[k].h;
      const ContactOutput ref = ContactLaws::eval(c[k].p, c[k].k, h);
      const auto at = [&](const Vec3T<T>& a) { return lane(a, k); };
      ASSERT_TRUE(same_bits(at(out.force), ref.force)) << "contact " << t0 + k;
      ASSERT_TRUE(same_bits(at(out.moment), ref.moment)) << "contact " << t0 + k;
      ASSERT_TRUE(same_bits(lane(out.fn, k), ref.fn)) << "contact " << t0 + k;
      ASSERT_TRUE(same_bits(at(H.fs), h.fs)) << "contact " << t0 + k;
      ASSERT_TRUE(same_bits(at(H.mr), h.mr)) << "contact " << t0 + k;
      for (int s = 0; s < kHistorySlots; ++s)
        ASSERT_TRUE(same_bits(lane(H.slot[s], k), h.slot[s])) << "contact " << t0 + k << ", " << kHistorySlotNames[s];
      ASSERT_EQ(lane(H.flags, k), h.flags) << "contact " << t0 + k;
    }
  }
}

// Rows loaded as lanes are the rows (lane k = row s0 + k, each component in place), a store puts them back, and
// the minimum image of a pack is that of each lane: across the half length, on it, and past it either way.
TEST(SimdLanes, RowsAndMinimumImageMatchTheScalarPath) {
  using T = ContactPack;
  const int n = 3 * kContactLanes + 1;
  Vec3View v("rows", n), back("back", n);
  auto hv = Kokkos::create_mirror_view(v);
  for (int s = 0; s < n; ++s)
    for (int d = 0; d < 3; ++d) hv(s, d) = 10 * s + d;
  Kokkos::deep_copy(v, hv);
  auto hb = Kokkos::create_mirror_view(back);
  for (int s0 = 0; s0 + kContactLanes <= n; s0 += kContactLanes) {
    const Vec3T<T> a = load_rows<T>(hv, s0);
    for (int k = 0; k < kContactLanes; ++k) ASSERT_TRUE(same_bits(lane(a, k), load(hv, s0 + k))) << "row " << s0 + k;
    store_rows(hb, s0, a);
  }
  for (int s = 0; s < n - n % kContactLanes; ++s) ASSERT_TRUE(same_bits(load(hb, s), load(hv, s))) << "row " << s;

  Domain dom;
  dom.hi[0] = 2.0; dom.hi[1] = 3.0; dom.hi[2] = 1.0;
  dom.periodic[0] = dom.periodic[1] = true;  // z open: never shifted
  const MinImage image(dom);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-2.5, 2.5);
  const double edge[] = {1.0, -1.0, 1.5, -1.5, 0.0};  // exactly half a length: not shifted
  for (int t = 0; t < 4000; ++t) {
    Vec3 d[kContactLanes];
    for (int k = 0; k < kContactLanes; ++k) {
      d[k] = Vec3(u(rng), u(rng), u(rng));
      if (t % 5 == 0) d[k].x = edge[(t / 5 + k) % 5];
      if (t % 7 == 0) d[k].y = edge[(t / 7 + k) % 5];
    }
    const Vec3T<T> got = image(vec_of_lanes<T>([&](int k) { return d[k]; }));
    for (int k = 0; k < kContactLanes; ++k) {
      const Vec3 want = image(d[k]);
      ASSERT_LE(std::abs(want.x), 1.0);  // the scalar path is the minimum image itself
      ASSERT_LE(std::abs(want.y), 1.5);
      ASSERT_TRUE(same_bits(want.z, d[k].z));
      ASSERT_TRUE(same_bits(lane(got, k), want)) << "case " << t;
    }
  }
}
#endif

/// Results of the kernel for every contact of a list, by key.
struct KernelResult {
  std::vector<Vec3> fs, mr, fc, mo, mt;
  std::vector<double> fn;
  std::vector<double> slot[kHistorySlots];
  std::vector<int> flags;
};

KernelResult run_kernel(const Particles& p, const std::vector<std::uint64_t>& keys, const ParamTableView& table) {
  ContactList c(static_cast<int>(keys.size()));
  auto hk = Kokkos::create_mirror_view(c.key);
  auto hi = Kokkos::create_mirror_view(c.i), hj = Kokkos::create_mirror_view(c.j);
  auto hfs = Kokkos::create_mirror_view(c.fs), hmr = Kokkos::create_mirror_view(c.mr);
  for (std::size_t s = 0; s < keys.size(); ++s) {
    hk(s) = keys[s];
    hi(s) = static_cast<int>(key_hi(keys[s]));  // gids are local indices here
    hj(s) = static_cast<int>(key_lo(keys[s]));
    // Some history, the same for a key in any order and different in each component, so that a row or a component
    // loaded into another lane or slot changes the result.
    for (int d = 0; d < 3; ++d) {
      hfs(s, d) = 1e-4 * static_cast<double>((keys[s] + d) % 7);
      hmr(s, d) = 1e-8 * static_cast<double>((keys[s] + 2 * d) % 5);
    }
  }
  Kokkos::deep_copy(c.key, hk);
  Kokkos::deep_copy(c.i, hi);
  Kokkos::deep_copy(c.j, hj);
  Kokkos::deep_copy(c.fs, hfs);
  Kokkos::deep_copy(c.mr, hmr);
  compute_ball_forces(p, c, table, Domain(), 1e-7);
  const auto v3 = [&](const Vec3View& v) {
    auto h = Kokkos::create_mirror_view_and_copy(HostSpace(), v);
    std::vector<Vec3> out(keys.size());
    for (std::size_t s = 0; s < keys.size(); ++s) out[s] = load(h, static_cast<int>(s));
    return out;
  };
  KernelResult r{v3(c.fs), v3(c.mr), v3(c.fc), v3(c.mo), v3(c.mt), {}, {}, {}};
  auto fn = Kokkos::create_mirror_view_and_copy(HostSpace(), c.fn);
  auto fl = Kokkos::create_mirror_view_and_copy(HostSpace(), c.flags);
  for (std::size_t s = 0; s < keys.size(); ++s) {
    r.fn.push_back(fn(s));
    r.flags.push_back(fl(s));
  }
  for (int q = 0; q < kHistorySlots; ++q) {
    auto h = Kokkos::create_mirror_view_and_copy(HostSpace(), c.slot[q]);
    r.slot[q].assign(h.data(), h.data() + keys.size());
  }
  return r;
}

/// Asserts that contact s of `ref` and contact q of `r` have the same bits everywhere.
void expect_same_contact(const KernelResult& r, std::size_t q, const KernelResult& ref, std::size_t s, const char* run) {
  ASSERT_TRUE(same_bits(r.fc[q], ref.fc[s]) && same_bits(r.mo[q], ref.mo[s]) && same_bits(r.mt[q], ref.mt[s]))
      << run << ": contact " << s;
  ASSERT_TRUE(same_bits(r.fs[q], ref.fs[s]) && same_bits(r.mr[q], ref.mr[s])) << run << ": contact " << s;
  ASSERT_TRUE(same_bits(r.fn[q], ref.fn[s])) << run << ": contact " << s;
  for (int k = 0; k < kHistorySlots; ++k)
    ASSERT_TRUE(same_bits(r.slot[k][q], ref.slot[k][s])) << run << ": contact " << s << ", " << kHistorySlotNames[k];
  ASSERT_EQ(r.flags[q], ref.flags[s]) << run << ": contact " << s;
}

// The same contacts, listed with one, two and three extra pairs in front (each contact moves to another lane and
// meets other pack-mates, some of which do not touch), give the same bits in the kernel. So does the list of the
// touching contacts alone: its packs are full and all touching, which the kernel stores as whole rows
// (store_rows), where the mixed packs of the full list store lane by lane.
TEST(SimdLanes, KernelResultDoesNotDependOnLaneOrPackMates) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  const double R = 1e-3;
  std::vector<BallSpec> b(60);
  for (std::size_t i = 0; i < b.size(); ++i) {  // a loose cloud: some pairs overlap, most do not
    b[i].x = 4 * R * Vec3(u(rng), u(rng), u(rng));
    b[i].v = 0.1 * Vec3(u(rng), u(rng), u(rng));
    b[i].w = 50 * Vec3(u(rng), u(rng), u(rng));
    b[i].radius = R * (1 + 0.3 * u(rng));
    b[i].material = static_cast<int>(i % 2);
  }
  const Particles p = make_particles(b);
  ParamTableView table("table", 2, 2);
  auto ht = Kokkos::create_mirror_view(table);
  ht(0, 0) = ht(1, 1) = test::law(1e8, 1.5, 0.3, 0.02);
  ht(0, 1) = ht(1, 0) = test::law(1e8, 1.5, 0.3, 0.02);
  ht(0, 1).wear = ht(1, 0).wear = 0.5;  // a second pair in some packs: lanes with other parameters
  ht(0, 1).twist = ht(1, 0).twist = 0.2;
  Kokkos::deep_copy(table, ht);
  std::vector<std::uint64_t> keys, touching;
  std::vector<std::size_t> touching_at;  // position of each touching pair in keys
  for (std::uint32_t i = 0; i < b.size(); ++i)
    for (std::uint32_t j = i + 1; j < b.size(); ++j) {
      const double gap = norm(b[j].x - b[i].x) - b[i].radius - b[j].radius;
      if (gap >= 0.5 * R) continue;
      if (gap < 0) {
        touching.push_back(pair_key(i, j));
        touching_at.push_back(keys.size());
      }
      keys.push_back(pair_key(i, j));
    }
  ASSERT_GT(touching.size(), 10u) << "test set-up: the cloud must hold touching pairs";
  ASSERT_LT(touching.size(), keys.size()) << "test set-up: and candidates that do not touch";
  const KernelResult ref = run_kernel(p, keys, table);

  for (int shift = 1; shift < 4; ++shift) {
    std::vector<std::uint64_t> shifted(keys.begin() + shift, keys.end());
    shifted.insert(shifted.end(), keys.begin(), keys.begin() + shift);  // the first ones last: another lane
    const KernelResult r = run_kernel(p, shifted, table);
    for (std::size_t s = 0; s < keys.size(); ++s)
      expect_same_contact(r, (s + keys.size() - shift) % keys.size(), ref, s, "shifted list");  // where keys[s] went
  }
  const KernelResult r = run_kernel(p, touching, table);
  for (std::size_t q = 0; q < touching.size(); ++q) expect_same_contact(r, q, ref, touching_at[q], "touching only");
}

/// The leapfrog of one particle as the scalar code spells it (kernels/motion/integrate.hpp before the lanes), for the
/// reference of the test below. The forces are summed as the gather sums them: the owner's side of its contacts in
/// key order, then the reactions of the others in contact order.
struct ScalarStep {
  Vec3 f, m, v, w, x;
  double vals[5];
};
double scalar_damping(double f, double v, double alpha) {
  const double s = v > 0 ? 1.0 : (v < 0 ? -1.0 : 0.0);
  return -alpha * std::fabs(f) * s;
}

// Particles advanced 4 (W) at a time, the last group partial, give each particle the bits of the scalar update:
// gather, gravity, local damping about a flow (zero velocity components included: sign 0), density scaling, and
// the step's values, summed in particle order.
TEST(SimdLanes, LeapfrogLanesGiveTheScalarUpdatesBits) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  const int n = 4 * kContactLanes + 3;
  std::vector<BallSpec> b(n);
  for (int i = 0; i < n; ++i) {
    b[i].x = 1e-2 * Vec3(u(rng), u(rng), u(rng));
    b[i].v = 0.1 * Vec3(i % 5 == 0 ? 0.0 : u(rng), u(rng), i % 3 == 0 ? 0.0 : u(rng));
    b[i].w = 50 * Vec3(u(rng), i % 4 == 0 ? 0.0 : u(rng), u(rng));
    b[i].radius = 1e-3 * (1 + 0.3 * u(rng));
  }
  Particles p = make_particles(b);
  // Hand-made contact results on pairs (i, i + 1) and (i, i + 3): their sums are the particles' forces.
  std::vector<std::pair<int, int>> pairs;
  for (int i = 0; i < n; ++i)
    for (int d : {1, 3})
      if (i + d < n) pairs.emplace_back(i, i + d);
  ContactList c(static_cast<int>(pairs.size()));
  auto hk = Kokkos::create_mirror_view(c.key);
  auto hi = Kokkos::create_mirror_view(c.i), hj = Kokkos::create_mirror_view(c.j);
  auto hfc = Kokkos::create_mirror_view(c.fc), hmo = Kokkos::create_mirror_view(c.mo), hmt = Kokkos::create_mirror_view(c.mt);
  for (std::size_t s = 0; s < pairs.size(); ++s) {
    hk(s) = pair_key(pairs[s].first, pairs[s].second);
    hi(s) = pairs[s].first;
    hj(s) = pairs[s].second;
    store(hfc, static_cast<int>(s), 1e-2 * Vec3(u(rng), u(rng), u(rng)));
    store(hmo, static_cast<int>(s), 1e-6 * Vec3(u(rng), u(rng), u(rng)));
    store(hmt, static_cast<int>(s), 1e-6 * Vec3(u(rng), u(rng), u(rng)));
  }
  Kokkos::deep_copy(c.key, hk);
  Kokkos::deep_copy(c.i, hi);
  Kokkos::deep_copy(c.j, hj);
  Kokkos::deep_copy(c.fc, hfc);
  Kokkos::deep_copy(c.mo, hmo);
  Kokkos::deep_copy(c.mt, hmt);
  const ContactList walls(0);
  const Gather g = make_gather(c, owner_ranges(p, c), build_adjacency(n, c, c.j), walls,
                               build_adjacency(n, walls, walls.i));
  IntegrateParams prm;
  prm.gravity = Vec3(0.3, -0.2, -9.81);
  prm.alpha = 0.7;
  prm.mass_scale = 3;
  prm.dt = 1e-5;
  prm.about_flow = true;
  prm.flow_rate = Vec3(0.1, 0.1, -0.2);
  prm.flow_origin = Vec3(0, 0, -1e-2);
  auto h = [](const auto& v) { return Kokkos::create_mirror_view_and_copy(HostSpace(), v); };
  auto x0 = h(p.x), v0 = h(p.v), w0 = h(p.w), xr = h(p.x_ref);
  auto mass = h(p.mass), inertia = h(p.inertia), radius = h(p.radius);
  std::vector<ScalarStep> want(n);
  std::vector<double> summed[3];
  double sums[5] = {0, 0, 0, 0, 0};
  for (int i = 0; i < n; ++i) {
    ScalarStep& r = want[i];
    for (std::size_t s = 0; s < pairs.size(); ++s)
      if (pairs[s].first == i) { r.f += load(hfc, static_cast<int>(s)); r.m += load(hmo, static_cast<int>(s)); }
    for (std::size_t s = 0; s < pairs.size(); ++s)
      if (pairs[s].second == i) { r.f -= load(hfc, static_cast<int>(s)); r.m += load(hmt, static_cast<int>(s)); }
    const double mi = mass(i), ii = inertia(i);
    const Vec3 force = r.f + mi * prm.gravity, x = load(x0, i);
    const Vec3 d = x - prm.flow_origin;
    const Vec3 vd = load(v0, i) - Vec3(prm.flow_rate.x * d.x, prm.flow_rate.y * d.y, prm.flow_rate.z * d.z);
    const double a = prm.dt / (mi * prm.mass_scale), bb = prm.dt / (ii * prm.mass_scale);
    const Vec3 w = load(w0, i);
    r.v = load(v0, i) + a * Vec3(force.x + scalar_damping(force.x, vd.x, prm.alpha),
                                 force.y + scalar_damping(force.y, vd.y, prm.alpha),
                                 force.z + scalar_damping(force.z, vd.z, prm.alpha));
    r.w = w + bb * Vec3(r.m.x + scalar_damping(r.m.x, w.x, prm.alpha), r.m.y + scalar_damping(r.m.y, w.y, prm.alpha),
                        r.m.z + scalar_damping(r.m.z, w.z, prm.alpha));
    r.x = x + prm.dt * r.v;
    const double vals[5] = {std::sqrt(dot(force, force)), 0.5 * (mi * dot(r.v, r.v) + ii * dot(r.w, r.w)), 0,
                            dot(r.x - load(xr, i), r.x - load(xr, i)),
                            dot(r.v, r.v) * (prm.dt * prm.dt) / (radius(i) * radius(i))};
    for (int q = 0; q < 3; ++q) summed[q].push_back(vals[q]);
    for (int q = 3; q < 5; ++q) sums[q] = std::max(sums[q], vals[q]);
  }
  for (int q = 0; q < 3; ++q) sums[q] = test::tree_sum(summed[q]);
  const StepStats st = integrate(p, Domain(), prm, g);
  auto x1 = h(p.x), v1 = h(p.v), w1 = h(p.w), f1 = h(p.f), m1 = h(p.m);
  for (int i = 0; i < n; ++i) {
    ASSERT_TRUE(same_bits(load(f1, i), want[i].f) && same_bits(load(m1, i), want[i].m)) << "gather, particle " << i;
    ASSERT_TRUE(same_bits(load(v1, i), want[i].v)) << "velocity, particle " << i;
    ASSERT_TRUE(same_bits(load(w1, i), want[i].w)) << "spin, particle " << i;
    ASSERT_TRUE(same_bits(load(x1, i), want[i].x)) << "position, particle " << i;
  }
  EXPECT_TRUE(same_bits(st.unbalanced, sums[0]));
  EXPECT_TRUE(same_bits(st.kinetic, sums[1]));
  EXPECT_TRUE(same_bits(st.max_disp2, sums[3]));
  EXPECT_TRUE(same_bits(st.max_move2, sums[4]));
  EXPECT_EQ(st.bad, -1);
}

}  // namespace
