#include "kernels/neighbor/contact_detect.hpp"

#include <algorithm>
#include <vector>

#include "kernels/core/buffers.hpp"
#include "kernels/core/reduce.hpp"

namespace dem {

namespace {

/// The count and fill passes shared by the searches. Derived provides visit(i, f), calling f(key) for each
/// candidate of particle i.
template <class Derived>
struct CountFill {
  struct TagCount {};
  struct TagFill {};
  IndexView count, offset;
  PairKeyView keys;

  KOKKOS_INLINE_FUNCTION const Derived& self() const { return static_cast<const Derived&>(*this); }
  KOKKOS_INLINE_FUNCTION void operator()(TagCount, const int i) const {
    int n = 0;
    self().visit(i, [&](std::uint64_t) { ++n; });
    count(i) = n;
  }
  KOKKOS_INLINE_FUNCTION void operator()(TagFill, const int i) const {
    int k = offset(i);
    self().visit(i, [&](std::uint64_t key) { keys(k++) = key; });
  }
};

/// Ball-ball search over the 27 neighbour cells of the particle's specimen's grid; each pair found once, from its
/// lower local index. A specimen not rebuilt gives its kept keys.
struct PairSearch : CountFill<PairSearch> {
  ConstVec3View x;
  ConstScalarView radius;
  GidView gid;
  ConstIndexView owner;
  IndexView cell_start;
  SpecimenCellsView specimens;
  PairKeyView kept;
  Index2View kept_own;

  template <class Visit>
  KOKKOS_INLINE_FUNCTION void visit(const int i, Visit&& f) const {
    const SpecimenCells& sc = specimens(owner(i));
    if (!sc.rebuild) {
      for (int k = kept_own(i, 0); k < kept_own(i, 1); ++k) f(kept(k));
      return;
    }
    const CellGrid& g = sc.grid;
    const MinImage image(sc.dom);
    const Vec3 xi = load(x, i);
    const int c[3] = {g.coord(0, xi.x), g.coord(1, xi.y), g.coord(2, xi.z)};
    for (int dz = -1; dz <= 1; ++dz) {
      const int cz = g.shift(2, c[2], dz);
      if (cz < 0) continue;
      for (int dy = -1; dy <= 1; ++dy) {
        const int cy = g.shift(1, c[1], dy);
        if (cy < 0) continue;
        for (int dx = -1; dx <= 1; ++dx) {
          const int cx = g.shift(0, c[0], dx);
          if (cx < 0) continue;
          const int cell = sc.first_cell + g.index(cx, cy, cz);
          for (int j = cell_start(cell); j < cell_start(cell + 1); ++j) {
            if (j <= i) continue;
            const Real reach = radius(i) + radius(j) + sc.skin;
            if (norm2(image(load(x, j) - xi)) < reach * reach) f(pair_key(gid(i), gid(j)));
          }
        }
      }
    }
  }
};

/// Ball-wall search: every analytic wall, plus the facets binned into the ball's cell.
struct WallSearch : CountFill<WallSearch> {
  ConstVec3View x;
  ConstScalarView radius;
  GidView gid;
  WallSet walls;
  FacetMesh mesh;
  IndexView fstart, ffacet;
  CellGrid g;
  Real skin;

  template <class Visit>
  KOKKOS_INLINE_FUNCTION void visit(const int i, Visit&& f) const {
    const Vec3 xi = load(x, i);
    const Real reach = radius(i) + skin;
    for (int w = 0; w < walls.n; ++w) {
      Vec3 n, cp;
      Real dist;
      if (wall_contact(walls.kind(w), load(walls.point, w), load(walls.normal, w), walls.radius(w), xi, n, dist, cp) &&
          dist < reach)
        f(wall_key(w, gid(i)));
    }
    if (mesh.ntri == 0) return;
    const int cell = g.cell_of(xi);
    for (int k = fstart(cell); k < fstart(cell + 1); ++k) {
      const int t = ffacet(k);
      if (norm2(facet_hit(mesh, t, xi).cp - xi) < reach * reach) f(wall_key(walls.n + t, gid(i)));
    }
  }
};

/// Counts each particle's candidates, scans the counts into offsets, fills the keys (into the buffers' next set)
/// and sorts them.
template <class Search>
PairKeyView run_search(Search s, int n, const char* label, ListBuffers* buffers) {
  ListBuffers own;
  ListBuffers& b = buffers ? *buffers : own;
  s.count = room(b.count, n, "dem::detect::count");
  Kokkos::parallel_for(label, Kokkos::RangePolicy<ExecSpace, typename Search::TagCount>(0, n), s);
  s.offset = room(b.offset, n + 1, "dem::detect::offset");
  const int total = exclusive_scan("dem::detect::scan", s.count, s.offset, n);
  s.keys = room(b.set[b.next].key, total, "dem::detect::keys");
  Kokkos::parallel_for(label, Kokkos::RangePolicy<ExecSpace, typename Search::TagFill>(0, n), s);
  sort_keys(s.keys, b.sort);
  return s.keys;
}

}  // namespace

FacetBins bin_facets(const FacetMesh& mesh, const CellGrid& g, Real reach, FacetBins& kept) {
  const int nc = g.ncell();
  const auto hx = kept_host_copy(kept.node_x_host, mesh.node_x);
  const auto ht = kept_host_copy(kept.tri_host, mesh.tri);
  std::vector<std::pair<int, int>> entries;  // (cell, facet)
  for (int t = 0; t < mesh.ntri; ++t) {
    int lo[3], hi[3];
    bool outside = false;
    for (int d = 0; d < 3; ++d) {
      Real a = hx(ht(t, 0), d), b = a;
      for (int v = 1; v < 3; ++v) { a = std::min(a, hx(ht(t, v), d)); b = std::max(b, hx(ht(t, v), d)); }
      a -= reach; b += reach;
      const Real glo = g.lo[d], ghi = g.lo[d] + g.h[d] * g.nc[d];
      if (!g.periodic[d] && (b < glo || a > ghi)) outside = true;
      lo[d] = g.coord(d, a);
      hi[d] = g.coord(d, b);
      if (g.periodic[d] && (b - a >= g.h[d] * g.nc[d] || hi[d] < lo[d])) { lo[d] = 0; hi[d] = g.nc[d] - 1; }
    }
    if (outside) continue;
    for (int cz = lo[2]; cz <= hi[2]; ++cz)
      for (int cy = lo[1]; cy <= hi[1]; ++cy)
        for (int cx = lo[0]; cx <= hi[0]; ++cx) entries.emplace_back(g.index(cx, cy, cz), t);
  }
  std::sort(entries.begin(), entries.end());
  FacetBins b;
  b.start = room(kept.start, nc + 1, "dem::detect::facet_start");
  b.facet = room(kept.facet, entries.size(), "dem::detect::facet");
  // Host Views of the whole buffers, which grow seldom; the bins' entries change in number at each rebuild.
  const auto hs_all = kept_mirror(kept.start_host, kept.start);
  const auto hf_all = kept_mirror(kept.facet_host, kept.facet);
  const auto hs = Kokkos::subview(hs_all, std::make_pair(std::size_t(0), b.start.extent(0)));
  const auto hf = Kokkos::subview(hf_all, std::make_pair(std::size_t(0), b.facet.extent(0)));
  std::size_t k = 0;
  for (int c = 0; c <= nc; ++c) {
    hs(c) = static_cast<int>(k);
    while (k < entries.size() && entries[k].first == c) { hf(k) = entries[k].second; ++k; }
  }
  Kokkos::deep_copy(b.start, hs);
  Kokkos::deep_copy(b.facet, hf);
  return b;
}

PairKeyView detect_pairs(const Particles& p, const CellList& cells, const PairKeyView& kept,
                         const Index2View& kept_own, ListBuffers* buffers) {
  PairSearch s;
  s.x = p.x; s.radius = p.radius; s.gid = p.gid; s.owner = p.specimen; s.cell_start = cells.cell_start;
  s.specimens = cells.specimens; s.kept = kept; s.kept_own = kept_own;
  return run_search(s, p.n, "dem::detect::pairs", buffers);
}

PairKeyView detect_wall_pairs(const Particles& p, const WallSet& walls, const FacetMesh& mesh,
                              const FacetBins& bins, const CellList& cells, Real skin, ListBuffers* buffers) {
  WallSearch s;
  s.x = p.x; s.radius = p.radius; s.gid = p.gid; s.walls = walls; s.mesh = mesh;
  s.fstart = bins.start; s.ffacet = bins.facet; s.g = cells.grid; s.skin = skin;
  return run_search(s, p.n, "dem::detect::walls", buffers);
}

}  // namespace dem
