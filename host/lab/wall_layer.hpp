#pragma once
/// The walls' looser layer of a walled cell and the void ratio a walled specimen of another size would have
/// (host/lab/state_match.cpp matches a walled cell smaller than the data's specimen on it).
///
/// A plane wall leaves a layer of balls packed looser than the interior, a few diameters deep and the same for any
/// size of specimen; its share of the specimen falls as area over volume, 1/L, so as N^-1/3. With the solid
/// fraction phi = phi_bulk - sum over the six walls of their deficits, the slab of a cell more than
/// kWallLayerDiameters from both walls of axis d lacks that axis's deficit alone, and
///   D = sum_d (phi_slab_d - phi_cell)
/// is the three axes' deficit in the whole cell. A specimen of N_data balls between walls then has
///   phi(N_data) = phi_cell + D (1 - (N_cell / N_data)^(1/3)).
/// Each slab's solid volume is exact (sphere_slab_volume), so D holds no counting error of balls cut by a plane.
/// The law is the faces' share alone: on triaxdem's walled cells (500 and 4,000 balls, one preparation) the larger
/// cells' interior also packed denser and their D fell 2.3-2.9 times, not 2 (the edges' share falls as N^-2/3), so
/// phi(N_data) takes away about 60% of a smaller cell's miss of a larger one's void ratio, not all of it.
#include <array>
#include <vector>

#include "host/engine/builder.hpp"

namespace dem {

/// How far (in mean ball diameters) a wall's looser layer reaches into a packing: monodisperse and narrowly graded
/// balls against a plane wall order into layers whose density oscillates and settles to the interior's within 2-3
/// diameters, most of the deficit lying in the first; 2 keeps 60% of a 1,000-ball cell's side (10 diameters) in
/// each slab. The cut's place along the layers' oscillation moves D: on cells of 500 balls, margins of 1 to 3
/// diameters gave D 0.024-0.038, 2 the largest (docs/prediction.md, The walls' layer).
inline constexpr Real kWallLayerDiameters = 2;

/// Whether a specimen of `data_balls` is larger than a cell of `cell_balls` (false for NaN): within a percent (a data
/// file's count against a config's) the two are one size, and a walled cell has no other size to be matched to.
inline bool larger_specimen(Real data_balls, Real cell_balls) { return data_balls > cell_balls * 1.01; }

/// D above: the walls' deficit in solid fraction of the balls packed in a walled cell [0, cell) (m).
Real wall_layer_deficit(const std::vector<BallSpec>& balls, const std::array<Real, 3>& cell);

/// The void ratio the balls packed in a walled cell [0, cell) would have as a specimen of `data_balls` balls
/// prepared alike: phi(N_data) above. `data_balls` equal to the balls' count gives the cell's own void ratio.
Real void_ratio_at_size(const std::vector<BallSpec>& balls, const std::array<Real, 3>& cell, Real data_balls);

}  // namespace dem
