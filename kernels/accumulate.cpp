#include "accumulate.hpp"

#include "vec3.hpp"

namespace dem {

Adjacency build_adjacency(int n, const ContactList& c, bool two_sided) {
  Adjacency a{IndexView("dem::accumulate::offset", n + 1), IndexView("dem::accumulate::entry", 0)};
  auto off = a.offset;
  auto ci = c.i, cj = c.j;
  Kokkos::parallel_for("dem::accumulate::count", RangePolicy(0, c.n), KOKKOS_LAMBDA(const int k) {
    Kokkos::atomic_increment(&off(ci(k)));
    if (two_sided) Kokkos::atomic_increment(&off(cj(k)));
  });
  int total = 0;
  Kokkos::parallel_scan("dem::accumulate::scan", RangePolicy(0, n + 1),
      KOKKOS_LAMBDA(const int i, int& acc, const bool final) {
        const int cnt = i < n ? off(i) : 0;
        if (final) off(i) = acc;
        acc += cnt;
      }, total);
  a.entry = IndexView("dem::accumulate::entry", total);
  auto entry = a.entry;
  IndexView cursor("dem::accumulate::cursor", n);
  Kokkos::parallel_for("dem::accumulate::fill", RangePolicy(0, c.n), KOKKOS_LAMBDA(const int k) {
    entry(off(ci(k)) + Kokkos::atomic_fetch_add(&cursor(ci(k)), 1)) = 2 * k;
    if (two_sided) entry(off(cj(k)) + Kokkos::atomic_fetch_add(&cursor(cj(k)), 1)) = 2 * k + 1;
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
  return a;
}

void gather_forces(Particles& p, const ContactList& balls, const Adjacency& ab, const ContactList& walls,
                   const Adjacency& aw) {
  auto f = p.f, m = p.m;
  auto bfc = balls.fc, bm1 = balls.m1, bm2 = balls.m2, wfc = walls.fc, wm1 = walls.m1;
  auto boff = ab.offset, bent = ab.entry, woff = aw.offset, went = aw.entry;
  Kokkos::parallel_for("dem::accumulate::gather", RangePolicy(0, p.n), KOKKOS_LAMBDA(const int i) {
    Vec3 fi, mi;
    for (int a = boff(i); a < boff(i + 1); ++a) {
      const int k = bent(a) >> 1;
      if (bent(a) & 1) { fi -= load(bfc, k); mi += load(bm2, k); }
      else { fi += load(bfc, k); mi += load(bm1, k); }
    }
    for (int a = woff(i); a < woff(i + 1); ++a) {
      const int k = went(a) >> 1;
      fi += load(wfc, k);
      mi += load(wm1, k);
    }
    store(f, i, fi);
    store(m, i, mi);
  });
}

IndexView object_offsets(const ContactList& walls, int nobj) {
  IndexView off("dem::accumulate::object_offsets", nobj + 1);
  auto key = walls.key;
  const int n = walls.n;
  Kokkos::parallel_for("dem::accumulate::object_offsets", RangePolicy(0, nobj + 1), KOKKOS_LAMBDA(const int o) {
    const std::uint64_t k = std::uint64_t(o) << 32;
    int lo = 0, hi = n;
    while (lo < hi) {
      const int mid = (lo + hi) / 2;
      if (key(mid) < k) lo = mid + 1; else hi = mid;
    }
    off(o) = lo;
  });
  return off;
}

void wall_forces_into(const ContactList& walls, const IndexView& offsets, Vec3View& out) {
  const int nobj = static_cast<int>(offsets.extent(0)) - 1;
  if (static_cast<int>(out.extent(0)) != nobj) out = Vec3View("dem::accumulate::wall_force", nobj);
  auto fc = walls.fc;
  auto res = out;
  Kokkos::parallel_for("dem::accumulate::wall_force", RangePolicy(0, nobj), KOKKOS_LAMBDA(const int o) {
    Vec3 s;
    for (int k = offsets(o); k < offsets(o + 1); ++k) s -= load(fc, k);
    store(res, o, s);
  });
}

}  // namespace dem
