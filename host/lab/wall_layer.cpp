/// The walls' layer of a walled cell (wall_layer.hpp).
#include "host/lab/wall_layer.hpp"

#include <cmath>

#include "host/triax/specimen.hpp"

namespace dem {

namespace {
/// D against the cell's own solid fraction phi_cell.
Real deficit_against(const std::vector<BallSpec>& balls, const std::array<Real, 3>& cell, Real phi_cell) {
  if (balls.empty()) return 0;
  Real radii = 0;
  for (const BallSpec& b : balls) radii += b.radius;
  const Real margin = kWallLayerDiameters * 2 * radii / static_cast<Real>(balls.size());
  const Real volume = cell[0] * cell[1] * cell[2];
  Real deficit = 0;
  for (int d = 0; d < 3; ++d) {
    const Real lo = margin, hi = cell[static_cast<std::size_t>(d)] - margin;
    if (hi <= lo) continue;  // a cell too thin for an interior: no layer can be told from it
    Real solid = 0;
    for (const BallSpec& b : balls) solid += sphere_slab_volume(b.x[d], b.radius, lo, hi);
    deficit += solid / (volume * (hi - lo) / cell[static_cast<std::size_t>(d)]) - phi_cell;
  }
  return deficit;
}

Real solid_fraction(const std::vector<BallSpec>& balls, const std::array<Real, 3>& cell) {
  return solid_volume(balls) / (cell[0] * cell[1] * cell[2]);
}
}  // namespace

Real wall_layer_deficit(const std::vector<BallSpec>& balls, const std::array<Real, 3>& cell) {
  return deficit_against(balls, cell, solid_fraction(balls, cell));
}

Real void_ratio_at_size(const std::vector<BallSpec>& balls, const std::array<Real, 3>& cell, Real data_balls) {
  const Real phi_cell = solid_fraction(balls, cell);
  const Real shrink = std::cbrt(static_cast<Real>(balls.size()) / data_balls);
  return 1 / (phi_cell + deficit_against(balls, cell, phi_cell) * (1 - shrink)) - 1;
}

}  // namespace dem
