#pragma once
/// Host-side construction of device state: particles, walls and facet meshes from plain vectors.
#include <vector>

#include "kernels/core/particles.hpp"
#include "kernels/core/walls.hpp"

namespace dem {

/// One ball on the host. Mass and inertia follow from radius and density (solid sphere).
struct BallSpec {
  Vec3 x, v, w;
  Real radius = 0;       ///< m
  Real density = 2500;   ///< kg/m^3
  int material = 0;
  int specimen = 0;
};

/// One analytic wall on the host (see WallKind).
struct WallSpec {
  int kind = kPlane;
  Vec3 point, normal, velocity;
  Real radius = 0;
  int material = 0;
};

/// The balls' total volume (m^3): solid spheres.
Real solid_volume(const std::vector<BallSpec>& balls);

/// Particles with gids 0..n-1 in the given order.
Particles make_particles(const std::vector<BallSpec>& balls);

/// Puts balls in the cell list's own order (slabs of `cell` along z, rows of `cell` along y, then x), so
/// that gids given in this order follow space. Contacts are stored by gid and balls visited in cell order:
/// when the two agree the force loop streams through memory; a specimen poured at random visits its
/// contacts at random (half the throughput at 54,000 balls). Stable, so equal keys keep their order.
void sort_like_cells(std::vector<BallSpec>& balls, Real cell);
WallSet make_walls(const std::vector<WallSpec>& walls);
/// nodes: n*3 coordinates (m); tris: m*3 node indices.
FacetMesh make_mesh(const std::vector<Real>& nodes, const std::vector<int>& tris, int material);

/// Copies of particle state to the host, indexed by gid (independent of the current sort order).
struct HostParticles {
  std::vector<Vec3> x, v, w;
};
HostParticles to_host_by_gid(const Particles& p);

}  // namespace dem
