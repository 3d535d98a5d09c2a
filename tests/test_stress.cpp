// Love-Weber contact stress and homogeneous cell deformation.
#include <gtest/gtest.h>

#include <cmath>

#include "host/engine/builder.hpp"
#include "host/engine/simulation.hpp"
#include "test_util.hpp"

using namespace dem;

namespace {

/// n^3 simple cubic lattice of pitch `pitch` in a periodic cube: every ball presses its 6 neighbours.
Simulation lattice(int n, double R, double pitch, double emod) {
  std::vector<BallSpec> b;
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        BallSpec s;
        s.x = Vec3((x + 0.5) * pitch, (y + 0.5) * pitch, (z + 0.5) * pitch);
        s.radius = R;
        b.push_back(s);
      }
  SimParams prm;
  prm.integ.gravity = Vec3();
  prm.integ.alpha = 0;
  prm.skin = 0.1 * R;
  for (int d = 0; d < 3; ++d) {
    prm.domain.hi[d] = n * pitch;
    prm.domain.periodic[d] = true;
  }
  Simulation sim(make_particles(b), WallSet(), FacetMesh(), {test::law(emod, 1.5, 0.5, 0.0)}, 1, prm);
  sim.set_dt(1e-9);
  return sim;
}

}  // namespace

TEST(Stress, LoveWeberOfCubicLatticeIsAnalytic) {
  // Each ball owns three contacts (one per axis) of force kn * overlap and branch length `pitch`, so
  // sigma_xx = n^3 kn overlap pitch / (n pitch)^3 = kn overlap / pitch^2; shear stresses vanish by symmetry.
  const double R = 1e-3, pitch = 1.99e-3, emod = 1e8;
  Simulation sim = lattice(4, R, pitch, emod);
  sim.step();
  const auto s = sim.contact_stress(sim.domain().volume());
  const double kn = test::kPi * R * emod / 2;
  const double expect = kn * (2 * R - pitch) / (pitch * pitch);
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(s[4 * a], expect, 1e-9 * expect);  // rounding of a few hundred terms
    for (int b = 0; b < 3; ++b)
      if (a != b) EXPECT_NEAR(s[3 * a + b], 0.0, 1e-12 * expect);
  }
}

TEST(Stress, StretchingTheCellRelievesTheLattice) {
  // Extension along z at 10/s for 100 steps of 1 ns stretches the cell by (1 + 1e-8)^100 and every
  // z-spacing with it; the z stress falls by kn * pitch * dstrain / pitch^2 while x and y stay (to first
  // order: the particles have not moved relative to the affine field in so short a time).
  const double R = 1e-3, pitch = 1.99e-3, emod = 1e8;
  Simulation sim = lattice(4, R, pitch, emod);
  sim.step();
  const double L0 = sim.domain().length(2);
  sim.set_strain_rate(Vec3(0, 0, 10));
  sim.run(100);
  const double stretch = std::pow(1 + 10 * 1e-9, 100);
  EXPECT_NEAR(sim.domain().length(2), L0 * stretch, 1e-15 * L0);
  sim.set_strain_rate(Vec3());
  sim.step();
  const auto s = sim.contact_stress(sim.domain().volume());
  const double kn = test::kPi * R * emod / 2;
  const double pz = pitch * stretch;
  // Closed forms on the stretched cell (volume n^2 pitch^2 n pz): the z contacts carry kn (2R - pz) over branch
  // pz, so sigma_zz = kn (2R - pz) / pitch^2; the x and y contacts are unchanged, so their stress falls with the
  // volume alone, sigma_xx = sigma_0 / stretch. The relief is 2e-4 sigma_0 along z and 1e-6 sigma_0 across; both
  // are asked to a thousandth of their size, far above the rounding of positions (1e-19 m against overlaps of
  // 1e-5 m) and far below what a wrong stretch (a relief of half the size, or none) would give.
  const double sigma0 = kn * (2 * R - pitch) / (pitch * pitch);
  const double zz = kn * (2 * R - pz) / (pitch * pitch), xx = sigma0 / stretch;
  EXPECT_NEAR(s[8], zz, 1e-3 * (sigma0 - zz));
  EXPECT_NEAR(s[0], xx, 1e-3 * (sigma0 - xx));
  EXPECT_NEAR(s[4], xx, 1e-3 * (sigma0 - xx));
}
