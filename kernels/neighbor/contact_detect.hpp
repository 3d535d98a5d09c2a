#pragma once
/// Candidate contacts by count -> exclusive scan -> fill -> sort: no guessed capacity, no retry loop,
/// and the sorted keys make the order independent of threads.
#include "kernels/neighbor/binning.hpp"
#include "kernels/neighbor/contact_list.hpp"
#include "kernels/core/walls.hpp"

namespace dem {

/// Facets listed per particle cell: a facet appears in every cell its bounding box, grown by
/// `reach` (largest radius + skin), overlaps, so a ball only looks in its own cell.
struct FacetBins {
  IndexView start;   ///< ncell + 1 offsets
  IndexView facet;
  /// bin_facets' host Views, kept in the caller's FacetBins between rebuilds (a GPU's host copies are allocations).
  IndexView::HostMirror start_host, facet_host;
  Vec3View::HostMirror node_x_host;
  Index3View::HostMirror tri_host;
};

/// Bins the mesh's facets into the cells of `grid` (on the host: a membrane has a few thousand facets), into the
/// first entries of `kept`'s Views (grown where short: room).
FacetBins bin_facets(const FacetMesh& mesh, const CellGrid& grid, Real reach, FacetBins& kept);

/// Keys of all ball-ball pairs whose centres are closer than r_i + r_j + skin, sorted: the cells' specimens' pairs,
/// each in its cell with its skin. A specimen that is not rebuilt keeps its keys of the list `kept`, whose owner
/// ranges for the particles' present order are `kept_own` (owner_ranges). With `buffers`, the search's scratch and
/// the keys are those of the list's rebuilds (ListBuffers), for remap_history with the same buffers.
PairKeyView detect_pairs(const Particles& p, const CellList& cells, const PairKeyView& kept = PairKeyView(),
                         const Index2View& kept_own = Index2View(), ListBuffers* buffers = nullptr);

/// Keys of all ball-wall pairs (analytic walls, then facets as objects walls.n + f) within skin, sorted; `buffers`
/// as detect_pairs.
PairKeyView detect_wall_pairs(const Particles& p, const WallSet& walls, const FacetMesh& mesh,
                              const FacetBins& bins, const CellList& cells, Real skin, ListBuffers* buffers = nullptr);

/// Centre-to-surface distance of a ball to facet f (closest point on the triangle).
KOKKOS_INLINE_FUNCTION FacetHit facet_hit(const FacetMesh& mesh, int f, const Vec3& x) {
  return closest_on_triangle(x, load(mesh.node_x, mesh.tri(f, 0)), load(mesh.node_x, mesh.tri(f, 1)),
                             load(mesh.node_x, mesh.tri(f, 2)));
}

}  // namespace dem
