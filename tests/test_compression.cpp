// Compression tests of a cell (host/triax/compression_test.hpp): the oedometer and the isotropic compression against
// a packing whose stresses follow from its contact geometry and springs, and a random packing's K0 against Jaky's.
#include <gtest/gtest.h>

#include <cmath>

#include "host/engine/packing.hpp"
#include "host/triax/compression_test.hpp"
#include "host/triax/periodic_triaxial.hpp"
#include "kernels/contact/contact_law.hpp"
#include "test_lattice.hpp"
#include "test_util.hpp"

using namespace dem;

namespace {

constexpr Real kD = 2e-3;  // m

/// A face-centred cubic packing of n^3 cubic cells (4 balls each, edge a = sqrt(2) d between touching neighbours),
/// pressed 0.1% so that every one of the 12 contacts of a ball carries load from the start.
std::vector<BallSpec> fcc(int n, std::array<Real, 3>& box) {
  const Real a = std::sqrt(Real(2)) * kD * 0.999;
  const Real basis[4][3] = {{0, 0, 0}, {0.5, 0.5, 0}, {0.5, 0, 0.5}, {0, 0.5, 0.5}};
  std::vector<BallSpec> balls;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k)
        for (const auto& b : basis) {
          BallSpec s;
          s.x = Vec3((i + b[0] + 0.25) * a, (j + b[1] + 0.25) * a, (k + b[2] + 0.25) * a);
          s.radius = kD / 2;
          s.density = 2500;
          balls.push_back(s);
        }
  box = {n * a, n * a, n * a};
  return balls;
}

PeriodicTriaxialParams seated_at(Real sigma) {
  PeriodicTriaxialParams p;
  p.verbose = false;
  p.sigma3 = sigma;
  p.consolidation_rate = 1;  // 1/s: the lattice is packed from the start
  p.axial_rate = 0.1;        // only resolve_periodic_params' defaults read it
  p.allow_high_inertial = true;
  return p;
}

}  // namespace

// The face-centred cubic packing deforms affinely under any uniform strain (each ball is a centre of symmetry of its
// 12 neighbours, and the fabric sum n (x) n is isotropic, so the tangential springs' moments cancel too). Along a
// cube axis, a neighbour at unit normal n adds d^2 eps [kn n_z^4 + ks n_z^2 (1 - n_z^2)] to V sigma_zz and
// d^2 eps n_x^2 n_z^2 (kn - ks) to V sigma_xx, V = d^3 / sqrt(2) a ball's share; over the 12 neighbours, each contact
// counted once:
//   one-dimensional strain:  d sigma_v = sqrt(2) (kn + ks) d eps_a / d,  d sigma_h / d sigma_v = (kn - ks) / (2 (kn + ks));
//   isotropic strain:        d p = 2 sqrt(2) kn d eps / d,  eps_v = 3 eps.
// Friction 1 keeps the tangential springs elastic (their force is (ks / kn) = 0.67 of the normal increment), and
// without rolling resistance nothing else acts. Tolerance 1%: the strains are below 0.2%, and what is linear in
// them here is exact up to the change of the branch vectors, of that order.
TEST(Compression, AFaceCentredCubicPackingFollowsItsSprings) {
  const ContactParams law = test::law(1e8, 1.5, 1.0, 0);
  const Real kn = NormalElastic::servo_stiffness(law, kD / 2, kD / 2), ks = kn / law.kratio;
  for (const CompressionPath path : {CompressionPath::oedometer, CompressionPath::isotropic}) {
    std::array<Real, 3> box{};
    const std::vector<BallSpec> balls = fcc(3, box);
    auto sim = make_periodic_simulation(balls, box, law, test::cell_solver());
    const CompressionResult r = run_compression_test(*sim, seated_at(50e3), path, {100e3, 200e3});
    ASSERT_EQ(r.series.size(), 3u);
    const CompressionRecord& a = r.series[1];
    const CompressionRecord& b = r.series[2];
    if (path == CompressionPath::oedometer) {
      EXPECT_NEAR(b.eps_v, b.eps_a, 1e-12) << "the lateral lengths are held";
      const Real modulus = (b.sigma_v - a.sigma_v) / (b.eps_a - a.eps_a);
      EXPECT_NEAR(modulus, std::sqrt(Real(2)) * (kn + ks) / kD, 0.01 * modulus);
      EXPECT_NEAR((b.sigma_h - a.sigma_h) / (b.sigma_v - a.sigma_v), (kn - ks) / (2 * (kn + ks)), 0.01 * 0.1);
    } else {
      const Real modulus = (b.p - a.p) / ((b.eps_v - a.eps_v) / 3);
      EXPECT_NEAR(modulus, 2 * std::sqrt(Real(2)) * kn / kD, 0.01 * modulus);
      EXPECT_NEAR(b.q, 0, 0.01 * b.p) << "an isotropic packing stays isotropic";
    }
    EXPECT_LT(b.void_ratio, a.void_ratio);
  }
}

// Unloading returns the lattice along its springs: the oedometer's void ratio back at the seating stress within the
// tolerance of its stress (0.5%) times the strain at that stress, since nothing slides.
TEST(Compression, AnElasticPackingUnloadsAlongItsLoadingPath) {
  const ContactParams law = test::law(1e8, 1.5, 1.0, 0);
  std::array<Real, 3> box{};
  const std::vector<BallSpec> balls = fcc(3, box);
  auto sim = make_periodic_simulation(balls, box, law, test::cell_solver());
  const CompressionResult r =
      run_compression_test(*sim, seated_at(50e3), CompressionPath::oedometer, {200e3, 50e3});
  ASSERT_EQ(r.series.size(), 3u);
  const Real loaded = r.series[1].eps_a;
  EXPECT_GT(loaded, 0);
  EXPECT_NEAR(r.series[2].eps_a, 0, 0.02 * loaded);
}

// Between walls: a simple cubic lattice of n^3 balls of radius r (WalledCell.ServoHoldsALatticeAtItsAnalyticSize's
// lattice), whose every column carries F = sigma L_a L_b / n^2 through n - 1 ball-ball springs of kn = pi r E / 2 and
// two ball-wall springs of kw = pi r E, so that its side along an axis is L = 2 n r - F ((n - 1) / kn + 2 / kw). Its
// contacts lie along the axes: an axial load moves no lateral contact.
//   oedometer:  the lateral sides held at the seating L0, the axial side from its column's F = sigma_v L0^2 / n^2, so
//               d sigma_v / d eps_a = n^2 / (L0 ((n - 1) / kn + 2 / kw)); the lateral forces stay the seating ones,
//               so sigma_h times the axial side is unchanged;
//   isotropic:  every side at the fixed point of L(sigma) (the one WalledCell solves), eps_v = 1 - (L / L0)^3.
// Tolerances: the servo holds each stress within stress_tolerance (0.5%) of its target, which moves each side by 0.5%
// of its compression; the moduli come from the stresses measured, so 1% covers the change of the sides (0.3%) and the
// walls' resting drift; the isotropic strain from the targets, 0.5% of a squeeze at each end of a difference of about
// half the larger: 2%.
TEST(Compression, ALatticeBetweenWallsFollowsItsColumns) {
  constexpr int n = 4;
  constexpr Real r = 1e-3, E = 1e8, gap = 1.01;
  const std::vector<BallSpec> balls = test::cubic_lattice(n, r, gap);
  const Real kn = M_PI * r * E / 2, kw = M_PI * r * E, compliance = (n - 1) / kn + 2 / kw;
  auto side_at = [&](Real sigma) {  // an isotropic stress's side
    Real L = 2 * n * r;
    for (int it = 0; it < 50; ++it) L = 2 * n * r - sigma * L * L / (n * n) * compliance;
    return L;
  };
  for (const CompressionPath path : {CompressionPath::oedometer, CompressionPath::isotropic}) {
    const Real side = gap * 2 * n * r;
    auto sim = make_periodic_simulation(balls, {side, side, side}, test::law(E, 1.5, 0.3, 0), test::cell_solver(),
                                        CellBoundary::walls);
    PeriodicTriaxialParams p = seated_at(100e3);
    p.consolidation_rate = 20;  // from a lattice 1% short of its walls
    const CompressionResult res = run_compression_test(*sim, p, path, {200e3, 300e3});
    ASSERT_EQ(res.series.size(), 3u) << path_name(path);
    const CompressionRecord& a = res.series[1];
    const CompressionRecord& b = res.series[2];
    const Real L0 = side_at(100e3);
    if (path == CompressionPath::oedometer) {
      const Real modulus = (b.sigma_v - a.sigma_v) / (b.eps_a - a.eps_a);
      EXPECT_NEAR(modulus, n * n / (L0 * compliance), 0.01 * modulus);
      EXPECT_NEAR(b.sigma_h * (1 - b.eps_a), res.series[0].sigma_h, 1e-3 * res.series[0].sigma_h)
          << "the lateral contacts carry the seating forces";
    } else {
      for (const CompressionRecord* x : {&a, &b}) {
        const Real eps_v = 1 - std::pow(side_at(x->target) / L0, 3);
        EXPECT_NEAR(x->eps_v, eps_v, 0.02 * eps_v) << x->target;
      }
    }
  }
}

TEST(Compression, AnUnknownPathOrABadTargetIsRefused) {
  EXPECT_THROW(compression_path("triaxial"), std::invalid_argument);
  EXPECT_EQ(compression_path("isotropic"), CompressionPath::isotropic);
  std::array<Real, 3> box{};
  const std::vector<BallSpec> balls = fcc(2, box);
  auto sim = make_periodic_simulation(balls, box, test::law(1e8, 1.5, 1.0, 0), test::cell_solver());
  EXPECT_THROW(run_compression_test(*sim, seated_at(50e3), CompressionPath::oedometer, {100e3, -1}),
               std::invalid_argument);
}
