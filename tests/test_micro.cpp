// Micromechanics (host/engine/micro.hpp) against sets with known answers: anisotropy recovered from sampled
// contact sets, coordination and networks on hand-built graphs, the cube cut and the force-chain file.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

#include "host/engine/micro.hpp"
#include "host/engine/stress.hpp"
#include "host/triax/micro_report.hpp"
#include "test_util.hpp"

using namespace dem;

namespace {

/// a diag(-1/2, -1/2, 1) * 2/3: axisymmetric about z, deviatoric, with signed magnitude a.
Tensor axial(Real a) { return {-a / 3, 0, 0, 0, -a / 3, 0, 0, 0, 2 * a / 3}; }

Real quad(const Tensor& a, const Vec3& n) {
  Real s = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) s += a[3 * i + j] * n[i] * n[j];
  return s;
}

/// n contacts whose normals follow E(n) = (1 + ac:nn)/4pi (rejection sampling), with normal force
/// f0 (1 + an:nn) and tangential force f0 (at.n - (n.at.n) n): the model of Ouadfel & Rothenburg.
ContactSet sampled(int n, Real ac, Real an, Real at, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<Real> g(0, 1);
  std::uniform_real_distribution<Real> u(0, 1);
  const Tensor Ac = axial(ac), An = axial(an), At = axial(at);
  const Real f0 = 2.0;
  ContactSet s;
  s.x.assign(2, Vec3());
  s.radius.assign(2, 1e-3);
  const Real emax = 1 + 2 * std::fabs(ac);
  while (static_cast<int>(s.contacts.size()) < n) {
    Vec3 v(g(rng), g(rng), g(rng));
    v = (1 / norm(v)) * v;
    if (u(rng) * emax > 1 + quad(Ac, v)) continue;
    ContactRecord c;
    c.a = 0;
    c.b = 1;
    c.normal = v;
    c.branch = 2e-3 * v;
    c.fn = f0 * (1 + quad(An, v));
    const Vec3 atn(At[0] * v.x, At[4] * v.y, At[8] * v.z);  // At is diagonal
    c.ft = f0 * (atn - quad(At, v) * v);
    s.contacts.push_back(c);
  }
  return s;
}

ContactRecord contact(int a, int b, Real fn, Boundary bd = Boundary::kNone) {
  ContactRecord c;
  c.a = a;
  c.b = b;
  c.boundary = bd;
  c.normal = Vec3(0, 0, 1);
  c.branch = Vec3(0, 0, 2e-3);
  c.fn = fn;
  return c;
}

}  // namespace

// The estimators against sets sampled from known second-order distributions (a_c 0.5, a_n 0.8, a_t 0.3), with
// tolerances from their measured sampling scatter: 24 sets of 10,000 contacts give each estimator's standard
// deviation s. Each mean must be the truth within 4 s / sqrt(24) (an estimator's bias: the set is exactly
// second order, so none is expected), and each set within 4 s (about 1 in 16,000 by chance per value). The
// scatter itself is bounded by the closed form for a_c: Var(n_z^2) = 1/5 - 1/9 = 4/45, so a_c = (3/2)(15/2)
// dev(phi)_zz scatters by about (45/4) sqrt(4/45 / N) = 0.034 at N = 10,000.
TEST(Micro, AnisotropyOfASampledSetIsRecovered) {
  constexpr int kSets = 24, kN = 10000;
  const std::array<Real, 3> truth{0.5, 0.8, 0.3};
  std::array<std::vector<Real>, 3> est;
  for (int k = 0; k < kSets; ++k) {
    const ContactSet s = sampled(kN, truth[0], truth[1], truth[2], 100 + k);
    const Anisotropy a = anisotropy(s, Network::kAll, Tensor{});
    est[0].push_back(a.a_c);
    est[1].push_back(a.a_n);
    est[2].push_back(a.a_t);
    EXPECT_NEAR(a.fabric[0] + a.fabric[4] + a.fabric[8], 1.0, 1e-12);
    EXPECT_NEAR(a.f0, 2.0, 0.05);
    if (k == 0) {
      // The stress-force-fabric relation q/p = (2/5)(a_c + a_n + 3/2 a_t) holds for this model set, where the
      // branch length is constant: checked against the Love-Weber stress of the same contacts.
      const Tensor sig = love_weber(s, 1.0, false);
      const Real p = (sig[0] + sig[4] + sig[8]) / 3, q = sig[8] - (sig[0] + sig[4]) / 2;
      EXPECT_NEAR(q / p, 0.4 * (a.a_c + a.a_n + 1.5 * a.a_t), 0.05);
    }
  }
  const char* names[3] = {"a_c", "a_n", "a_t"};
  for (int q = 0; q < 3; ++q) {
    Real mean = 0, ss = 0;
    for (Real x : est[q]) mean += x / kSets;
    for (Real x : est[q]) ss += (x - mean) * (x - mean);
    const Real sd = std::sqrt(ss / (kSets - 1));
    std::printf("%s: mean %.4f (truth %.2f), sd %.4f over %d sets of %d contacts\n", names[q], mean, truth[q], sd,
                kSets, kN);
    EXPECT_NEAR(mean, truth[q], 4 * sd / std::sqrt(Real(kSets))) << names[q] << ": biased";
    for (Real x : est[q]) EXPECT_NEAR(x, truth[q], 4 * sd) << names[q];
    EXPECT_LT(sd, 0.06) << names[q] << ": scatters more than twice the closed form for a_c";
  }
}

TEST(Micro, IsotropicSetHasNoAnisotropyAndSignFollowsTheStress) {
  const ContactSet s = sampled(40000, 0, 0, 0, 11);
  const Anisotropy a = anisotropy(s, Network::kAll, Tensor{});
  EXPECT_LT(std::fabs(a.a_c), 0.07);
  EXPECT_LT(std::fabs(a.a_n), 0.07);
  EXPECT_LT(std::fabs(a.a_t), 0.07);
  // Contacts aligned with x under compression along z: negative (extension-like) fabric anisotropy.
  const ContactSet lateral = sampled(20000, -0.4, 0, 0, 3);
  EXPECT_NEAR(anisotropy(lateral, Network::kAll, axial(1)).a_c, -0.4, 0.07);
}

TEST(Micro, CoordinationOfAHandBuiltGraph) {
  // Balls 0-1-2-3 in a chain, ball 4 alone; ball 0 touches the membrane, ball 3 a platen.
  ContactSet s;
  s.x.assign(5, Vec3());
  s.radius.assign(5, 1e-3);
  s.contacts = {contact(0, 1, 1), contact(1, 2, 1), contact(2, 3, 1), contact(0, -1, 1, Boundary::kMembrane),
                contact(3, -1, 1, Boundary::kPlaten)};
  const Coordination z = coordination(s);
  EXPECT_DOUBLE_EQ(z.z, 2.0 * 4 / 5);       // 3 ball-ball + 1 membrane contact; the platen is not counted
  EXPECT_DOUBLE_EQ(z.z_balls, 2.0 * 3 / 5);
  EXPECT_DOUBLE_EQ(z.z_mech, (6.0 - 2) / (5 - 1 - 2));  // N0 = 1 (ball 4), N1 = 2 (balls 0 and 3)
  ASSERT_EQ(z.on.size(), 3u);
  EXPECT_EQ(z.on[0], 1);  // ball 4
  EXPECT_EQ(z.on[1], 1);  // ball 3 (its platen contact does not count)
  EXPECT_EQ(z.on[2], 3);  // balls 0 (one ball + the membrane), 1, 2
}

TEST(Micro, StrongAndWeakNetworksSplitAtTheMeanForce) {
  ContactSet s;
  s.x.assign(5, Vec3());
  s.radius.assign(5, 1e-3);
  s.contacts = {contact(0, 1, 1), contact(1, 2, 2), contact(2, 3, 3), contact(3, 4, 6),
                contact(4, -1, 100, Boundary::kMembrane)};  // boundary contacts stay out of the split
  s.contacts[3].ft = Vec3(0.5, 0, 0);
  s.contacts[0].ft = Vec3(0, 0.1, 0);
  const Networks w = networks(s, 1e-6);
  EXPECT_DOUBLE_EQ(w.threshold, 3.0);
  EXPECT_EQ(w.strong.contacts, 1);   // fn = 6 > 3
  EXPECT_EQ(w.weak.contacts, 3);     // 1, 2 and 3 (a force equal to the mean is weak)
  EXPECT_EQ(w.strong.particles, 2);
  EXPECT_EQ(w.weak.particles, 4);
  EXPECT_DOUBLE_EQ(w.strong.mean_fn, 6.0);
  EXPECT_DOUBLE_EQ(w.weak.mean_fn, 2.0);
  EXPECT_DOUBLE_EQ(w.fn_ratio, 3.0);
  EXPECT_DOUBLE_EQ(w.ft_ratio, 0.5 / (0.1 / 3));
  // Partial stresses add up to the whole: sigma_zz = sum fn * 2 mm / V.
  EXPECT_NEAR(w.strong.stress[8] + w.weak.stress[8], w.all.stress[8], 1e-9);
  EXPECT_NEAR(w.all.stress[8], 12 * 2e-3 / 1e-6, 1e-6);
  const Coordination zs = coordination(s, Network::kStrong);
  EXPECT_DOUBLE_EQ(zs.z, 2.0 * 2 / 5);  // the strong ball-ball contact and the strong membrane contact
}

TEST(Micro, RoseIntegratesToOneAndFollowsTheFabric) {
  const ContactSet s = sampled(40000, 0.5, 0, 0, 5);
  const auto r = rose(s, 18);
  Real integral = 0;
  for (const RoseBin& b : r) integral += b.density * 4 * M_PI / r.size();  // equal solid angles
  EXPECT_NEAR(integral, 1.0, 1e-12);
  // Each bin holds about 40,000 x 2 / 18 / 2 = 2,200 contacts (2% counting error): compare every bin's
  // density with (1 + a (cos^2 - 1/3))/4pi at its centre, within 8% (the bin average of cos^2 differs from
  // its centre value by up to 2% in the widest, equatorial bins).
  for (const RoseBin& b : r) {
    const Real c = std::cos(b.theta_deg * M_PI / 180);
    EXPECT_NEAR(b.density, (1 + 0.5 * (c * c - 1.0 / 3)) / (4 * M_PI), 0.08 / (4 * M_PI)) << b.theta_deg;
  }
  EXPECT_NEAR(r.front().theta_deg + r.back().theta_deg, 180.0, 1e-9);  // symmetric about the equator
}

TEST(Micro, CubeCutKeepsInsideContactsAndRefusesAnOversizedCube) {
  ContactSet s;
  for (int k = 0; k < 10; ++k) {
    s.x.push_back(Vec3(0, 0, 2e-3 * k));
    s.radius.push_back(1.2e-3);  // a column 2.4 mm wide
  }
  for (int k = 0; k + 1 < 10; ++k) {
    ContactRecord c = contact(k, k + 1, 1.0 + k);
    c.point = Vec3(0, 0, 2e-3 * k + 1e-3);
    s.contacts.push_back(c);
  }
  const ContactSet cube = restrict_to_cube(s, Vec3(0, 0, 9e-3), 2.2e-3);  // z in [7.9, 10.1] mm: balls 4, 5
  EXPECT_EQ(std::count(cube.inside.begin(), cube.inside.end(), 1), 2);
  // Contact averages see only the contact at z = 9 mm (between balls 4 and 5) ...
  const Networks w = networks(cube, 1.0);
  EXPECT_EQ(w.all.contacts, 1);
  EXPECT_DOUBLE_EQ(w.all.mean_fn, 5.0);
  // ... while each ball inside keeps both its contacts for its own count (O_2 = 2, Z_mech = 2), and
  // 2 Nc / Np = 2 x 1 / 2 counts the contacts inside.
  const Coordination z = coordination(cube);
  EXPECT_DOUBLE_EQ(z.z, 1.0);
  EXPECT_DOUBLE_EQ(z.z_mech, 2.0);
  ASSERT_EQ(z.on.size(), 3u);
  EXPECT_EQ(z.on[2], 2);
  try {
    restrict_to_cube(s, Vec3(0, 0, 9e-3), 20e-3);
    FAIL() << "a 20 mm cube does not fit in a 2 mm wide column";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("20 mm"), std::string::npos) << e.what();
  }
}

TEST(Micro, ForceChainFileListsEverySegment) {
  ContactSet s;
  s.x = {Vec3(0, 0, 0), Vec3(0, 0, 2e-3), Vec3(0, 0, 4e-3)};
  s.radius.assign(3, 1e-3);
  s.contacts = {contact(0, 1, 1), contact(1, 2, 3), contact(2, -1, 9, Boundary::kPlaten)};
  const auto path = dem::test::scratch_dir("chains") / "chains.vtk";
  write_force_chains_vtk(path.string(), s);
  std::ifstream f(path);
  const std::string text((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("POINTS 4 double"), std::string::npos);
  EXPECT_NE(text.find("LINES 2 6"), std::string::npos);
  EXPECT_NE(text.find("SCALARS strong int 1\nLOOKUP_TABLE default\n0\n1\n"), std::string::npos) << text;
}

TEST(Micro, SurfaceVolumeOfAPrismIsExact) {
  // An open 12-sided tube between z = 1 and 3 mm (as a membrane between the platens): the enclosed volume
  // is the inscribed prism, (n/2) R^2 sin(2 pi/n) H, to rounding.
  const int n = 12;
  const Real R = 5e-3, z0 = 1e-3, H = 2e-3;
  io::SurfaceSnapshot s;
  for (int ring = 0; ring < 2; ++ring)
    for (int k = 0; k < n; ++k) {
      const Real a = 2 * M_PI * k / n;
      s.nodes.insert(s.nodes.end(), {R * std::cos(a), R * std::sin(a), z0 + ring * H});
    }
  for (int k = 0; k < n; ++k) {
    const int a = k, b = (k + 1) % n, c = n + k, d = n + (k + 1) % n;
    s.triangles.insert(s.triangles.end(), {a, b, d, a, d, c});  // counter-clockwise seen from outside
  }
  EXPECT_NEAR(surface_volume(s), 0.5 * n * R * R * std::sin(2 * M_PI / n) * H, 1e-15);
}
