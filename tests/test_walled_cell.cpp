// The cell test between six rigid walls (host/triax/cell_boundary.hpp, [periodic] boundary = "walls"): the wall servo
// against a lattice whose size under load is known in closed form, and the average-stress theorem at the walls.
#include <gtest/gtest.h>

#include <cmath>

#include "host/triax/cell_boundary.hpp"
#include "host/engine/micro.hpp"
#include "host/engine/stress.hpp"
#include "host/engine/packing.hpp"
#include "host/triax/periodic_triaxial.hpp"
#include "host/engine/simulation.hpp"
#include "host/triax/triaxial_measure.hpp"
#include "test_lattice.hpp"
#include "test_util.hpp"

using namespace dem;

namespace {

constexpr Real kR = 1e-3, kE = 1e8, kSigma3 = 100e3;

PeriodicTriaxialParams quiet() {
  PeriodicTriaxialParams p;
  p.verbose = false;
  p.sigma3 = kSigma3;
  p.target_inertial = 9e-4;
  p.record_strain = 0.001;
  return p;
}

}  // namespace

// A simple cubic lattice of n^3 balls of radius r between the walls, compressed isotropically: every column of n
// balls carries F = sigma3 L^2 / n^2 through n - 1 ball-ball springs of kn = pi r E / 2 and two ball-wall springs of
// pi r E (kernels/contact/contact_law.hpp: pi r^2 E / (r1 + r2), r1 at a wall), so L = 2 n r - F ((n - 1) / kn + 2 / kw),
// solved with F by fixed-point iteration. The servo stops within stress_tolerance (0.5%) of sigma3, so each side
// lies within 0.5% of the lattice's compression of the analytic length (0.6% allowed for the last step's drift).
// The servo's stiffness is the walls' exactly: n^2 kw on a wall, K = n^2 kw L / (2 L^2). Rates set are rates read,
// the walls moving apart symmetrically.
TEST(WalledCell, ServoHoldsALatticeAtItsAnalyticSize) {
  const int n = 4;
  const Real gap = 1.01;  // the lattice starts unloaded, the walls 1% beyond it
  const std::vector<BallSpec> balls = test::cubic_lattice(n, kR, gap);
  const Real side = gap * 2 * n * kR;
  auto sim = make_periodic_simulation(balls, {side, side, side}, test::law(kE, 1.5, 0.3, 0), test::cell_solver(),
                                      CellBoundary::walls);
  ASSERT_TRUE(walled(*sim));
  PeriodicTriaxialParams p = quiet();
  p.consolidation_rate = 20;
  consolidate_isotropic(*sim, p);
  const Real kn = M_PI * kR * kE / 2, kw = M_PI * kR * kE;
  Real L = 2 * n * kR, F = 0;
  for (int it = 0; it < 50; ++it) {
    F = kSigma3 * L * L / (n * n);
    L = 2 * n * kR - F * ((n - 1) / kn + 2 / kw);
  }
  const Real squeeze = 2 * n * kR - L;
  const std::array<Real, 3> lengths = cell_lengths(*sim), stress = cell_stress(*sim);
  for (int d = 0; d < 3; ++d) {
    EXPECT_NEAR(stress[d], kSigma3, p.stress_tolerance * kSigma3) << "axis " << d;
    EXPECT_NEAR(lengths[d], L, 0.006 * squeeze) << "axis " << d << ": analytic " << L << " m, squeeze " << squeeze;
  }
  // Each contact's kn is read back as its force (of the last step) over its overlap (of now): the lattice, at
  // rest to the unbalanced ratio 1e-3, has moved by 1e-6 of an overlap since (seen: 1.6e-6); 1e-4 allowed.
  const std::array<Real, 3> K = boundary_stiffness(*sim);
  for (int d = 0; d < 3; ++d) {
    const Real expected = n * n * kw * lengths[d] / (2 * lengths[(d + 1) % 3] * lengths[(d + 2) % 3]);
    EXPECT_NEAR(K[d], expected, 1e-4 * expected) << "axis " << d;
  }
  set_cell_rates(*sim, Vec3(0.5, -0.25, 1.0));
  const Vec3 r = cell_rates(*sim);
  EXPECT_NEAR(r.x, 0.5, 1e-12);
  EXPECT_NEAR(r.y, -0.25, 1e-12);
  EXPECT_NEAR(r.z, 1.0, 1e-12);
  EXPECT_NEAR(sim->wall_velocity(0).x, -sim->wall_velocity(1).x, 1e-15);
}

// The average-stress theorem at the walls: over the box's volume, the Love-Weber stress of every contact (ball-ball
// on the centre-to-centre branch, ball-wall on the centre-to-contact-point one) equals the boundary's
// (1/V) sum x_c (x) f_c plus (1/V) sum x_p (x) F_p of the balls' net forces, to the 1e-4 p of rebuilding each force
// from its normal magnitude (the membrane test's allowance, test_triaxial.cpp). The stress the cell reports, the
// mean force of a pair of walls over the face area, is that boundary stress exactly where the pair's forces balance;
// they differ by the pair's imbalance times the box centre's coordinate, which is the balls' net force: within
// rounding of that term. Checked consolidated and part way through shear, where the balls accelerate.
TEST(WalledCell, WallStressIsLoveWebersOfAllContactsLessTheBallsNetForces) {
  Config cfg;
  cfg.particles.count = 200;
  cfg.particles.diameter = 2 * kR;
  const Real L = std::cbrt(200 * M_PI / 6 * 8e-9 / 0.2);
  cfg.box.size = {L, L, L};
  cfg.box.periodic = {false, false, false};
  cfg.run.seed = 3;
  PeriodicTriaxialParams p = quiet();
  p.consolidation_rate = 100;
  // Packed dense without friction (e about 0.6; with it a gas jams at e 1.0 and collapses under shear), then
  // given its friction.
  auto sim = make_periodic_simulation(make_packing(cfg), cfg.box.size, test::law(kE, 1.5, 0, 0), test::cell_solver(),
                                      CellBoundary::walls);
  p.unbalanced_tolerance = 5e-2;
  consolidate_isotropic(*sim, p);
  p.unbalanced_tolerance = 1e-3;
  std::array<Real, 3> cell{};
  const std::vector<BallSpec> dense = extract_balls(*sim, cell);
  sim = make_periodic_simulation(dense, cell, test::law(kE, 1.5, 0.3, 0.05), test::cell_solver(), CellBoundary::walls);
  p.target_strain = 0.02;
  for (int stage = 0; stage < 2; ++stage) {
    if (stage == 0) {
      consolidate_isotropic(*sim, p);
    } else {
      // The q a lab without area correction reports: the deviator force over the cross-section at the start of
      // shear, A0 = V0 / h0, where the walls' own q is over A = V / h, so q_fixed = q (1 - eps_v) / (1 - eps_a) on
      // every record, to rounding (1e-12 relative); the specimen bulges, so q_fixed exceeds q late in the shear.
      const PeriodicTriaxialResult r = run_periodic_triaxial(*sim, p);
      for (const PeriodicTriaxialRecord& row : r.series)
        EXPECT_NEAR(row.q_fixed_area, row.q * (1 - row.eps_v) / (1 - row.eps_a), 1e-12 * kSigma3) << row.eps_a;
      EXPECT_GT(r.series.back().q_fixed_area, r.series.back().q);
    }
    const Real V = cell_volume(*sim);
    const ContactSet cs = contact_set(*sim);
    // The specimen's stresses on the device (specimen_stress) against the same sums on the host, from the contacts
    // as copied (ContactSet) and from the balls' gathered forces. The boundary's and the net forces' differ only in
    // the order of the sums: 1e-10 of the pressure (a thousand terms of one sign add rounding of about 1e-13 of the
    // sum). The ContactSet rebuilds a ball-ball force from its elastic normal force along today's normal, which has
    // turned since the force was computed at the step's start (the walls' normals do not turn), so its Love-Weber
    // differs from the device's, which sums the forces as computed, by about |ft| times a step's turn per contact:
    // 1.6e-10 of the pressure at rest, 4.3e-7 in shear (measured); 1e-6 of it here. The device's own three obey the
    // average-stress theorem, its net term from the gathered forces and not from the contact terms.
    const SpecimenStress dev = specimen_stress(*sim, V);
    const Tensor lw = love_weber(cs, V, true), b = boundary_stress(cs, V);
    const Particles& pt = sim->particles_with_forces();
    auto f = Kokkos::create_mirror_view_and_copy(HostSpace(), pt.f);
    auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), pt.x);
    Tensor net{};
    for (int i = 0; i < pt.n; ++i)
      for (int k = 0; k < 9; ++k) net[k] += f(i, k / 3) * x(i, k % 3) / V;
    const Real pressure = mean_stress(lw);
    ASSERT_GT(pressure, 0.5 * kSigma3);
    for (int k = 0; k < 9; ++k) {
      EXPECT_NEAR(dev.boundary[k], b[k], 1e-10 * pressure) << "stage " << stage << ", component " << k;
      EXPECT_NEAR(dev.net_force[k], net[k], 1e-10 * pressure) << "stage " << stage << ", component " << k;
      EXPECT_NEAR(dev.love_weber[k], lw[k], 1e-6 * pressure) << "stage " << stage << ", component " << k;
      // The average-stress theorem: Love-Weber of every contact = the boundary's + the balls' net forces. The
      // balls are near rest, not at it: 1e-4 of the pressure (the net forces' q is printed below).
      EXPECT_NEAR(dev.love_weber[k], dev.boundary[k] + dev.net_force[k], 1e-4 * pressure)
          << "stage " << stage << ", component " << k;
      EXPECT_NEAR(lw[k], b[k] + net[k], 1e-4 * pressure) << "stage " << stage << ", component " << k;
    }
    // The balls' net force along d and the centre of the box along d: the pair-mean's departure from b_dd.
    const std::array<Real, 3> s = cell_stress(*sim);
    for (int d = 0; d < 3; ++d) {
      Real total = 0;
      for (int i = 0; i < pt.n; ++i) total += f(i, d);
      const Real centre = cell_corner(*sim)[d] + 0.5 * cell_lengths(*sim)[d];
      EXPECT_NEAR(s[d], b[4 * d] + centre * total / V, 1e-9 * pressure) << "stage " << stage << ", axis " << d;
    }
    std::printf("stage %d: walls q %.2f kPa, Love-Weber q of all contacts %.2f kPa, net forces' q %.3f kPa\n", stage,
                1e-3 * (s[2] - 0.5 * (s[0] + s[1])), 1e-3 * axial_deviator(lw), 1e-3 * axial_deviator(net));
  }
}
