#pragma once
/// Cell list by counting sort. Particles are re-sorted by cell (memory locality), ties broken by
/// global id so that the order, and everything computed from it, is the same for any thread count.
#include <vector>

#include "kernels/core/domain.hpp"
#include "kernels/core/particles.hpp"

namespace dem {

/// Uniform grid over the particles' bounding box (periodic axes: over the cell).
struct CellGrid {
  Real lo[3] = {0, 0, 0};
  Real h[3] = {1, 1, 1};   ///< cell edge (m), >= the contact cut-off
  int nc[3] = {1, 1, 1};
  bool periodic[3] = {false, false, false};

  KOKKOS_INLINE_FUNCTION int ncell() const { return nc[0] * nc[1] * nc[2]; }
  KOKKOS_INLINE_FUNCTION int coord(int d, Real x) const {
    int c = static_cast<int>(kc::floor((x - lo[d]) / h[d]));
    if (periodic[d]) { c %= nc[d]; if (c < 0) c += nc[d]; return c; }
    return c < 0 ? 0 : (c >= nc[d] ? nc[d] - 1 : c);
  }
  KOKKOS_INLINE_FUNCTION int index(int cx, int cy, int cz) const { return cx + nc[0] * (cy + nc[1] * cz); }
  KOKKOS_INLINE_FUNCTION int cell_of(const Vec3& x) const {
    return index(coord(0, x.x), coord(1, x.y), coord(2, x.z));
  }
  /// Neighbour cell coordinate c + off along axis d; -1 when it falls off a non-periodic edge.
  KOKKOS_INLINE_FUNCTION int shift(int d, int c, int off) const {
    int s = c + off;
    if (periodic[d]) return (s + nc[d]) % nc[d];
    return (s < 0 || s >= nc[d]) ? -1 : s;
  }
};

/// One specimen of a batch as the binning and the pair search see it (a simulation of one specimen has one): its
/// particles [first, first + count), its cell, its grid and first cell, its Verlet skin, and whether it is rebuilt
/// now. A specimen not rebuilt keeps its particles' order (a cell of its own for each) and its contact list.
struct SpecimenCells {
  Domain dom;
  CellGrid grid;
  int first = 0, count = 0;
  int first_cell = 0;
  Real skin = 0;  ///< m
  bool rebuild = true;
};
using SpecimenCellsView = Kokkos::View<SpecimenCells*, MemSpace>;

/// The binned particles: cell_start(c) .. cell_start(c+1) are the particles of cell c, in sorted order. The cells
/// of specimen s start at specimens(s).first_cell; `grid` is the first specimen's (for facets and walls, which
/// only a simulation of one specimen has).
struct CellList {
  CellGrid grid;
  SpecimenCellsView specimens;
  IndexView cell_start;
  /// The binning's scratch, kept for the next rebuild (buffers.hpp): cells, counts, cursors, the permutation, and
  /// the particles' other set of Views that the permutation writes to.
  IndexView cell_buf, start_buf, cursor_buf, perm_buf;
  SpecimenCellsView::HostMirror specimens_host;
  Particles spare;
};

/// A specimen to bin: its particles, its cell, the cut-off its cells must hold (m) and its skin (m); rebuild as in
/// SpecimenCells.
struct SpecimenBin {
  int first = 0, count = 0;
  Domain dom;
  Real cell_min = 0, skin = 0;
  bool rebuild = true;
};

/// Wraps periodic coordinates outside the cell (Domain::contain: the steps keep them inside), builds a grid with
/// cells of at least `cell_min`, sorts the particles by cell (permuting every per-particle View) and fills the cell
/// list, for a pair search within `skin`. Throws std::runtime_error when a periodic length holds fewer than 3 cells
/// (the minimum image would then be ambiguous).
void bin_particles(Particles& p, const Domain& dom, Real cell_min, Real skin, CellList& cells);
/// The same for the specimens of a batch, side by side, in one pass: each rebuilt specimen is binned in its own
/// grid as it would be alone (the same order, bit for bit), and the others keep their particles where they are.
/// Particle i must belong to specimen p.specimen(i), whose range holds it; there is at least one specimen.
void bin_specimens(Particles& p, const std::vector<SpecimenBin>& specimens, CellList& cells);

/// A ball whose centre lies more than `margin` times its radius outside the domain along a non-periodic axis
/// that has bounds (hi > lo; an axis without them is sized to the balls): its local index (the largest
/// such), or -1.
int ball_outside(const Particles& p, const Domain& dom, Real margin);

}  // namespace dem
