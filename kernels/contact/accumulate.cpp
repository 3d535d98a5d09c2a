#include "kernels/contact/accumulate.hpp"

#include "kernels/core/buffers.hpp"
#include "kernels/core/reduce.hpp"

namespace dem {

Adjacency build_adjacency(int n, const ContactList& c, const IndexView& side) {
  Adjacency a;
  build_adjacency(n, c, side, a);
  return a;
}

void build_adjacency(int n, const ContactList& c, const IndexView& side, Adjacency& a) {
  const IndexView off = same_size(a.offset, static_cast<std::size_t>(n) + 1, "dem::accumulate::offset");
  zero(off, "dem::accumulate::zero");
  Kokkos::parallel_for("dem::accumulate::count", RangePolicy(0, c.n),
                       KOKKOS_LAMBDA(const int k) { Kokkos::atomic_increment(&off(side(k))); });
  const int total = exclusive_scan("dem::accumulate::scan", off, off, n);
  a.entry = room(a.entry_buf, static_cast<std::size_t>(total), "dem::accumulate::entry");
  const IndexView entry = a.entry;
  const IndexView cursor = same_size(a.cursor, static_cast<std::size_t>(n), "dem::accumulate::cursor");
  zero(cursor, "dem::accumulate::zero");
  Kokkos::parallel_for("dem::accumulate::fill", RangePolicy(0, c.n), KOKKOS_LAMBDA(const int k) {
    entry(off(side(k)) + Kokkos::atomic_fetch_add(&cursor(side(k)), 1)) = k;
  });
  // Fill order follows thread timing; sorting each particle's short list makes the sum order fixed.
  Kokkos::parallel_for("dem::accumulate::order", RangePolicy(0, n), KOKKOS_LAMBDA(const int i) {
    for (int a2 = off(i) + 1; a2 < off(i + 1); ++a2) {
      const int v = entry(a2);
      int b = a2 - 1;
      while (b >= off(i) && entry(b) > v) { entry(b + 1) = entry(b); --b; }
      entry(b + 1) = v;
    }
  });
}

Index2View owner_ranges(const Particles& p, const ContactList& balls) {
  Index2View own;
  owner_ranges(p, balls, own);
  return own;
}

void owner_ranges(const Particles& p, const ContactList& balls, Index2View& own_out) {
  const Index2View own = same_size(own_out, static_cast<std::size_t>(p.n), "dem::accumulate::owner_ranges");
  auto key = balls.key;
  auto gid = p.gid;
  const int n = balls.n;
  Kokkos::parallel_for("dem::accumulate::owner_ranges", RangePolicy(0, p.n), KOKKOS_LAMBDA(const int i) {
    own(i, 0) = key_lower_bound(key, n, std::uint64_t(gid(i)) << 32);
    own(i, 1) = key_lower_bound(key, n, (std::uint64_t(gid(i)) + 1) << 32);
  });
}

Gather make_gather(const ContactList& balls, const Index2View& own, const Adjacency& ab, const ContactList& walls,
                   const Adjacency& aw) {
  return Gather{balls.fc, balls.mo, balls.mt, walls.fc, walls.mt, own, ab.offset, ab.entry, aw.offset, aw.entry};
}

IndexView object_offsets(const ContactList& walls, int nobj) {
  IndexView off;
  object_offsets(walls, nobj, off);
  return off;
}

void object_offsets(const ContactList& walls, int nobj, IndexView& off_out) {
  const IndexView off = same_size(off_out, static_cast<std::size_t>(nobj) + 1, "dem::accumulate::object_offsets");
  auto key = walls.key;
  const int n = walls.n;
  Kokkos::parallel_for("dem::accumulate::object_offsets", RangePolicy(0, nobj + 1), KOKKOS_LAMBDA(const int o) {
    off(o) = key_lower_bound(key, n, std::uint64_t(o) << 32);
  });
}

void wall_loads_into(const ContactList& walls, const IndexView& offsets, int nobj, WallLoadView& loads) {
  if (static_cast<int>(loads.extent(0)) < nobj) loads = WallLoadView("dem::accumulate::wall_loads", nobj);
  auto fc = walls.fc;
  auto fn = walls.fn;
  auto res = loads;
  Kokkos::parallel_for("dem::accumulate::wall_force", RangePolicy(0, nobj), KOKKOS_LAMBDA(const int o) {
    Vec3 s;
    int c = 0;
    for (int k = offsets(o); k < offsets(o + 1); ++k) {
      s -= load(fc, k);
      c += fn(k) > 0 ? 1 : 0;
    }
    WallLoad& w = res(o);
    w.force[0] = s.x;
    w.force[1] = s.y;
    w.force[2] = s.z;
    w.touching = c;
  });
}

}  // namespace dem
