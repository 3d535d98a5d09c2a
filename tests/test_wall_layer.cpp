// A walled cell's looser layer at its walls (host/lab/wall_layer.hpp), on a lattice whose deficit is known exactly.
#include <gtest/gtest.h>

#include <cmath>

#include "host/lab/wall_layer.hpp"

using namespace dem;

namespace {

constexpr Real kR = 1e-3, kSpacing = 2 * kR;
constexpr int kSide = 12;  // lattice sites a side: the slabs 2 diameters in span 8 of them

/// A simple cubic lattice of touching balls filling [0, 12 a)^3, its first layer along z left empty: a "wall layer"
/// one spacing deep at the z- wall alone, whose whole deficit in solid fraction is one layer's, phi_b / 12.
std::vector<BallSpec> lattice_with_empty_layer() {
  std::vector<BallSpec> balls;
  for (int i = 0; i < kSide; ++i)
    for (int j = 0; j < kSide; ++j)
      for (int k = 1; k < kSide; ++k) {
        BallSpec b;
        b.radius = kR;
        b.x = Vec3((i + 0.5) * kSpacing, (j + 0.5) * kSpacing, (k + 0.5) * kSpacing);
        balls.push_back(b);
      }
  return balls;
}

const std::array<Real, 3> kCell{kSide * kSpacing, kSide * kSpacing, kSide * kSpacing};
const Real kPhiBulk = M_PI / 6;  // a simple cubic lattice of touching spheres

}  // namespace

// The z slab [2a, 10a] holds eight whole layers (phi_b); the x and y slabs cut the missing layer as the whole cell
// does (11/12 phi_b each): D = phi_b / 12, all from z. The balls touch the slabs' planes, never cross them, so the
// exact sphere-slab volumes leave only rounding (1e-12).
TEST(WallLayer, ALatticesMissingLayerIsItsDeficit) {
  const std::vector<BallSpec> balls = lattice_with_empty_layer();
  EXPECT_NEAR(wall_layer_deficit(balls, kCell), kPhiBulk / kSide, 1e-12);
}

// A specimen of 8 times the balls has half the cell's side ratio of layer to volume: phi = (11/12 + 1/24) phi_b. Of
// the cell's own balls, the cell's own void ratio (V / V_solid - 1), so the match of a cell as large as the data's
// is the whole cell's.
TEST(WallLayer, ASpecimenOfEightTimesTheBallsHasHalfTheLayersShare) {
  const std::vector<BallSpec> balls = lattice_with_empty_layer();
  const Real n = static_cast<Real>(balls.size());
  EXPECT_NEAR(void_ratio_at_size(balls, kCell, 8 * n), 1 / (kPhiBulk * (11.0 / 12 + 1.0 / 24)) - 1, 1e-12);
  const Real own = kCell[0] * kCell[1] * kCell[2] / solid_volume(balls) - 1;
  EXPECT_NEAR(void_ratio_at_size(balls, kCell, n), own, 1e-12);
  // An infinite specimen: the interior alone, the lattice's bulk.
  EXPECT_NEAR(void_ratio_at_size(balls, kCell, INFINITY), 1 / kPhiBulk - 1, 1e-12);
}
