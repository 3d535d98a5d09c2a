#include "kernels/neighbor/binning.hpp"

#include "kernels/core/buffers.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace dem {

namespace {


/// The grid of a specimen's particles [first, first + count): their bounds are read only along an open axis.
CellGrid make_grid(const Particles& p, int first, int count, const Domain& dom, Real cell_min) {
  Real mn[3] = {0, 0, 0}, mx[3] = {0, 0, 0};
  auto x = p.x;
  for (int d = 0; d < 3; ++d) {
    if (dom.periodic[d] || count == 0) continue;
    Kokkos::MinMaxScalar<Real> r;
    Kokkos::parallel_reduce("dem::binning::bounds", RangePolicy(first, first + count),
        KOKKOS_LAMBDA(const int i, Kokkos::MinMaxScalar<Real>& acc) {
          acc.min_val = x(i, d) < acc.min_val ? x(i, d) : acc.min_val;
          acc.max_val = x(i, d) > acc.max_val ? x(i, d) : acc.max_val;
        },
        Kokkos::MinMax<Real>(r));
    mn[d] = r.min_val;
    mx[d] = r.max_val;
  }
  CellGrid g;
  long total = 1;
  for (int d = 0; d < 3; ++d) {
    g.periodic[d] = dom.periodic[d];
    if (dom.periodic[d]) {
      g.lo[d] = dom.lo[d];
      g.nc[d] = static_cast<int>(std::floor(dom.length(d) / cell_min));
      if (g.nc[d] < 3)
        throw std::runtime_error("periodic length along axis " + std::to_string(d) + " (" +
                                 std::to_string(dom.length(d)) + " m) must hold at least 3 contact cut-offs (" +
                                 std::to_string(3 * cell_min) + " m)");
      g.h[d] = dom.length(d) / g.nc[d];
    } else {
      g.lo[d] = mn[d];
      g.h[d] = cell_min;
      g.nc[d] = static_cast<int>(std::floor((mx[d] - mn[d]) / cell_min)) + 1;
    }
    total *= g.nc[d];
  }
  // A stray particle far away (or a sparse periodic box) would blow up the cell count; coarser cells
  // stay correct, only slower. Periodic axes keep at least 3 cells for the minimum image.
  const long cap = 8L * count + 4096;
  bool coarsened = true;
  while (total > cap && coarsened) {
    coarsened = false;
    total = 1;
    for (int d = 0; d < 3; ++d) {
      if (!g.periodic[d]) {
        g.h[d] *= 2;
        g.nc[d] = static_cast<int>(std::floor((mx[d] - mn[d]) / g.h[d])) + 1;
        coarsened = true;
      } else if (g.nc[d] / 2 >= 3) {
        g.nc[d] /= 2;
        g.h[d] = dom.length(d) / g.nc[d];
        coarsened = true;
      }
      total *= g.nc[d];
    }
  }
  return g;
}

}  // namespace

void bin_particles(Particles& p, const Domain& dom, Real cell_min, Real skin, CellList& cells) {
  bin_specimens(p, {SpecimenBin{0, p.n, dom, cell_min, skin, true}}, cells);
}

void bin_specimens(Particles& p, const std::vector<SpecimenBin>& specimens, CellList& cells) {
  const int ns = static_cast<int>(specimens.size());
  if (ns == 0) throw std::invalid_argument("bin_specimens: no specimen");
  if (static_cast<int>(cells.specimens.extent(0)) != ns)
    cells.specimens = SpecimenCellsView("dem::binning::specimens", ns);
  const auto hs = kept_mirror(cells.specimens_host, cells.specimens);
  int nc = 0;
  bool wrap = false;
  for (int s = 0; s < ns; ++s) {
    const SpecimenBin& b = specimens[static_cast<std::size_t>(s)];
    SpecimenCells& c = hs(s);
    c.dom = b.dom;
    c.first = b.first;
    c.count = b.count;
    c.skin = b.skin;
    c.rebuild = b.rebuild;
    c.first_cell = nc;
    if (b.rebuild) {
      c.grid = make_grid(p, b.first, b.count, b.dom, b.cell_min);
      nc += c.grid.ncell();
      wrap = wrap || b.dom.periodic[0] || b.dom.periodic[1] || b.dom.periodic[2];
    } else {
      nc += b.count;  // a cell for each particle: they keep their order
    }
  }
  Kokkos::deep_copy(cells.specimens, hs);
  const SpecimenCellsView spec = cells.specimens;
  auto x = p.x;
  auto owner = p.specimen;
  if (wrap) {
    Kokkos::parallel_for("dem::binning::wrap", RangePolicy(0, p.n), KOKKOS_LAMBDA(const int i) {
      const SpecimenCells& c = spec(owner(i));
      if (c.rebuild) store(x, i, c.dom.contain(load(x, i)));
    });
  }
  const IndexView cell = room(cells.cell_buf, p.n, "dem::binning::cell");
  const IndexView start = room(cells.start_buf, nc + 1, "dem::binning::cell_start");
  zero(start, "dem::binning::zero");
  Kokkos::parallel_for("dem::binning::count", RangePolicy(0, p.n), KOKKOS_LAMBDA(const int i) {
    const SpecimenCells& c = spec(owner(i));
    cell(i) = c.first_cell + (c.rebuild ? c.grid.cell_of(load(x, i)) : i - c.first);
    Kokkos::atomic_increment(&start(cell(i)));
  });
  Kokkos::parallel_scan("dem::binning::scan", RangePolicy(0, nc + 1),
      KOKKOS_LAMBDA(const int c, int& acc, const bool final) {
        const int cnt = c < nc ? start(c) : 0;
        if (final) start(c) = acc;
        acc += cnt;
      });
  const IndexView cursor = room(cells.cursor_buf, nc, "dem::binning::cursor");
  zero(cursor, "dem::binning::zero");
  const IndexView perm = room(cells.perm_buf, p.n, "dem::binning::perm");
  Kokkos::parallel_for("dem::binning::fill", RangePolicy(0, p.n), KOKKOS_LAMBDA(const int i) {
    const int c = cell(i);
    perm(start(c) + Kokkos::atomic_fetch_add(&cursor(c), 1)) = i;
  });
  // The atomic fill order depends on thread timing; sorting each (short) cell by gid removes that.
  auto gid = p.gid;
  Kokkos::parallel_for("dem::binning::order", RangePolicy(0, nc), KOKKOS_LAMBDA(const int c) {
    for (int a = start(c) + 1; a < start(c + 1); ++a) {
      const int v = perm(a);
      int b = a - 1;
      while (b >= start(c) && gid(perm(b)) > gid(v)) { perm(b + 1) = perm(b); --b; }
      perm(b + 1) = v;
    }
  });
  p.permute(perm, cells.spare);
  cells.grid = hs(0).grid;
  cells.cell_start = start;
}

int ball_outside(const Particles& p, const Domain& dom, Real margin) {
  bool bounded[3];
  for (int d = 0; d < 3; ++d) bounded[d] = !dom.periodic[d] && dom.hi[d] > dom.lo[d];
  if (!bounded[0] && !bounded[1] && !bounded[2]) return -1;
  auto x = p.x;
  auto r = p.radius;
  const Domain dm = dom;
  int worst = -1;
  Kokkos::parallel_reduce("dem::binning::outside", RangePolicy(0, p.n),
      KOKKOS_LAMBDA(const int i, int& acc) {
        bool out = false;
        for (int d = 0; d < 3; ++d)
          out = out || (bounded[d] && (x(i, d) < dm.lo[d] - margin * r(i) || x(i, d) > dm.hi[d] + margin * r(i)));
        if (out && i > acc) acc = i;
      }, Kokkos::Max<int>(worst));
  return worst >= 0 ? worst : -1;  // the reduction starts at INT_MIN
}

}  // namespace dem
