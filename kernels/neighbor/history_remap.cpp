#include "kernels/neighbor/history_remap.hpp"

#include "kernels/core/buffers.hpp"

namespace dem {

IndexView gid_to_local(const Particles& p) {
  IndexView map;
  gid_to_local(p, map);
  return map;
}

void gid_to_local(const Particles& p, IndexView& map_out) {
  const IndexView map = same_size(map_out, p.gid_bound(), "dem::remap::gid2local");
  auto gid = p.gid;
  Kokkos::parallel_for("dem::remap::clear", RangePolicy(0, static_cast<int>(map.extent(0))),
                       KOKKOS_LAMBDA(const int g) { map(g) = -1; });
  Kokkos::parallel_for("dem::remap::gid2local", RangePolicy(0, p.n), KOKKOS_LAMBDA(const int i) { map(gid(i)) = i; });
}

ContactList remap_history(const PairKeyView& keys, const ContactList& old, const IndexView& gid2local,
                          bool ball_ball) {
  const int n = static_cast<int>(keys.extent(0));
  ContactList c(n);
  c.key = keys;
  const int nold = old.n;
  auto okey = old.key;
  auto ofs = old.fs, omr = old.mr, ofc = old.fc, omo = old.mo, omt = old.mt;
  auto ofn = old.fn;
  auto oflags = old.flags;
  Kokkos::parallel_for("dem::remap::history", RangePolicy(0, n), KOKKOS_LAMBDA(const int k) {
    const std::uint64_t key = keys(k);
    if (ball_ball) {
      c.i(k) = gid2local(key_hi(key));
      c.j(k) = gid2local(key_lo(key));
    } else {
      c.i(k) = gid2local(key_lo(key));
      c.j(k) = static_cast<int>(key_hi(key));
    }
    const int lb = key_lower_bound(okey, nold, key);
    const int o = (lb < nold && okey(lb) == key) ? lb : -1;
    for (int d = 0; d < 3; ++d) {
      c.fs(k, d) = o >= 0 ? ofs(o, d) : Real(0);
      c.mr(k, d) = o >= 0 ? omr(o, d) : Real(0);
      c.fc(k, d) = o >= 0 ? ofc(o, d) : Real(0);
      c.mo(k, d) = o >= 0 ? omo(o, d) : Real(0);
      c.mt(k, d) = o >= 0 ? omt(o, d) : Real(0);
    }
    c.fn(k) = o >= 0 ? ofn(o) : Real(0);
    c.flags(k) = o >= 0 ? oflags(o) : std::uint8_t(0);
    for (int s = 0; s < kHistorySlots; ++s) c.slot[s](k) = o >= 0 ? old.slot[s](o) : Real(0);
  });
  return c;
}

}  // namespace dem
