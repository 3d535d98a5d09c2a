#include "kernels/neighbor/binning.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace dem {

namespace {


CellGrid make_grid(const Particles& p, const Domain& dom, Real cell_min) {
  Real mn[3], mx[3];
  auto x = p.x;
  for (int d = 0; d < 3; ++d) {
    Kokkos::MinMaxScalar<Real> r;
    Kokkos::parallel_reduce("dem::binning::bounds", RangePolicy(0, p.n),
        KOKKOS_LAMBDA(const int i, Kokkos::MinMaxScalar<Real>& acc) {
          acc.min_val = x(i, d) < acc.min_val ? x(i, d) : acc.min_val;
          acc.max_val = x(i, d) > acc.max_val ? x(i, d) : acc.max_val;
        },
        Kokkos::MinMax<Real>(r));
    mn[d] = p.n > 0 ? r.min_val : 0;
    mx[d] = p.n > 0 ? r.max_val : 0;
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
  const long cap = 8L * p.n + 4096;
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

void bin_particles(Particles& p, const Domain& dom, Real cell_min, CellList& cells) {
  auto x = p.x;
  if (dom.periodic[0] || dom.periodic[1] || dom.periodic[2]) {
    Kokkos::parallel_for("dem::binning::wrap", RangePolicy(0, p.n),
                         KOKKOS_LAMBDA(const int i) { store(x, i, dom.wrap(load(x, i))); });
  }
  const CellGrid g = make_grid(p, dom, cell_min);
  const int nc = g.ncell();
  IndexView cell("dem::binning::cell", p.n);
  IndexView start("dem::binning::cell_start", nc + 1);
  Kokkos::parallel_for("dem::binning::count", RangePolicy(0, p.n), KOKKOS_LAMBDA(const int i) {
    cell(i) = g.cell_of(load(x, i));
    Kokkos::atomic_increment(&start(cell(i)));
  });
  Kokkos::parallel_scan("dem::binning::scan", RangePolicy(0, nc + 1),
      KOKKOS_LAMBDA(const int c, int& acc, const bool final) {
        const int cnt = c < nc ? start(c) : 0;
        if (final) start(c) = acc;
        acc += cnt;
      });
  IndexView cursor("dem::binning::cursor", nc);
  IndexView perm("dem::binning::perm", p.n);
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
  p.permute(perm);
  cells.grid = g;
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
