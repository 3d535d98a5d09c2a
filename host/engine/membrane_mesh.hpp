#pragma once
/// The triaxial specimen's membrane as a triangulated cylinder (Tang et al. 2025: 81 nodes around,
/// 20 segments in height), and its device state.
#include <vector>

#include "kernels/motion/membrane.hpp"

namespace dem {

/// A cylinder surface about the z axis, on the host.
struct MembraneMesh {
  int n_around = 0, n_segments = 0;
  /// 3 coordinates per node (m), ring by ring from the bottom: node r * n_around + k is on ring r
  /// (z = z0 + r height / n_segments) at angle 2 pi k / n_around.
  std::vector<Real> nodes;
  /// 3 node ids per triangle, counter-clockwise seen from outside, so every area vector points away
  /// from the axis. Two per quad; quads of ring band r are triangles 2 (r n_around + k) and + 1.
  std::vector<int> tris;
  /// End-ring node ids in increasing angle: the order build_membrane and enclosed_volume expect.
  std::vector<int> bottom, top;

  int num_nodes() const { return static_cast<int>(nodes.size() / 3); }
  int num_tris() const { return static_cast<int>(tris.size() / 3); }
};

/// Triangulated cylinder of radius `radius` (m, nodes on the circle: the polygon is inscribed) from
/// z0 to z0 + height (m). The quad diagonals alternate ring band by ring band (see the .cpp for why).
/// Throws std::invalid_argument naming the parameter: n_around < 8, n_segments < 1, radius or
/// height not > 0, or more than 2^31 / 6 facets.
MembraneMesh make_cylinder_membrane(int n_around, int n_segments, Real radius, Real z0, Real height);

/// Device membrane for the mesh (reference state = the mesh as built, end rings fixed); `material`
/// is the facets' row of the contact-parameter table.
Membrane make_membrane(const MembraneMesh& mesh, const MembraneMaterial& mat, int material = 0);

}  // namespace dem
