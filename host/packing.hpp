#pragma once
/// Initial particle arrangements for a box: random sequential insertion (loose, any size spread) or a
/// jittered cubic lattice (dense, about 6 contacts per ball when the pitch is below the diameter).
#include <vector>

#include "config.hpp"
#include "host/builder.hpp"

namespace dem {

/// Balls for the config's [particles] and [box]. Throws ConfigError when the count cannot be placed.
std::vector<BallSpec> make_packing(const Config& cfg);

/// Plane walls on the non-periodic faces of the box (normals pointing inwards).
std::vector<WallSpec> box_walls(const Config& cfg);

}  // namespace dem
