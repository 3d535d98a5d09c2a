#pragma once
/// Initial particle arrangements for a box: random sequential insertion (loose, any size spread) or a
/// jittered cubic lattice (dense, about 6 contacts per ball when the pitch is below the diameter).
#include <random>
#include <vector>

#include "host/config/config.hpp"
#include "host/engine/builder.hpp"

namespace dem {

/// Where random insertion may put ball centres: the box [lo, hi], cut to a vertical cylinder of
/// `radius` about `axis` (x, y) when radius > 0; periodic axes wrap.
struct InsertRegion {
  Vec3 lo, hi;
  bool periodic[3] = {false, false, false};
  Vec3 axis;
  Real radius = 0;
};

/// Up to pc.count new balls (sizes and density from pc) at random free places of the region, avoiding
/// `existing` balls. Returns fewer when the region is full (about 0.3 solid fraction).
std::vector<BallSpec> insert_random(const ParticleConfig& pc, const InsertRegion& reg,
                                    const std::vector<BallSpec>& existing, std::mt19937_64& rng);

/// Balls for the config's [particles] and [box]. Throws ConfigError when the count cannot be placed.
std::vector<BallSpec> make_packing(const Config& cfg);

/// Plane walls on the non-periodic faces of the box (normals pointing inwards).
std::vector<WallSpec> box_walls(const Config& cfg);

}  // namespace dem
