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

namespace {

/// A list of n contacts over the arrays of `set`, grown where short.
ContactList list_in(ContactList& set, int n) {
  ContactList c;
  c.n = n;
  c.i = room(set.i, n, "dem::contacts::i");
  c.j = room(set.j, n, "dem::contacts::j");
  c.fs = room_rows(set.fs, n, "dem::contacts::fs");
  c.mr = room_rows(set.mr, n, "dem::contacts::mr");
  c.flags = room(set.flags, n, "dem::contacts::flags");
  c.fc = room_rows(set.fc, n, "dem::contacts::fc");
  c.mo = room_rows(set.mo, n, "dem::contacts::mo");
  c.mt = room_rows(set.mt, n, "dem::contacts::mt");
  c.fn = room(set.fn, n, "dem::contacts::fn");
  for (int s = 0; s < kHistorySlots; ++s) c.slot[s] = room(set.slot[s], n, "dem::contacts::slot");
  return c;
}

}  // namespace

ContactList remap_history(const PairKeyView& keys, const ContactList& old, const IndexView& gid2local,
                          bool ball_ball, ListBuffers* buffers) {
  const int n = static_cast<int>(keys.extent(0));
  ContactList c = buffers ? list_in(buffers->set[buffers->next], n) : ContactList(n);
  if (buffers) buffers->next = 1 - buffers->next;
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
