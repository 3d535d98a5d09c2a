#pragma once
/// Candidate contacts (pairs within the Verlet skin) with their history, one record per physical
/// contact, sorted by key. Ball-ball key: min_gid << 32 | max_gid. Ball-wall key: object << 32 | gid,
/// where object numbers the analytic walls first, then the facets; sorting by it groups each wall's
/// contacts, so wall forces are summed in a fixed order.
#include "kernels/core/types.hpp"

namespace dem {

KOKKOS_INLINE_FUNCTION std::uint64_t pair_key(std::uint32_t a, std::uint32_t b) {
  return a < b ? (std::uint64_t(a) << 32) | b : (std::uint64_t(b) << 32) | a;
}
KOKKOS_INLINE_FUNCTION std::uint64_t wall_key(int object, std::uint32_t gid) {
  return (std::uint64_t(object) << 32) | gid;
}
KOKKOS_INLINE_FUNCTION std::uint32_t key_hi(std::uint64_t k) { return static_cast<std::uint32_t>(k >> 32); }
KOKKOS_INLINE_FUNCTION std::uint32_t key_lo(std::uint64_t k) { return static_cast<std::uint32_t>(k & 0xffffffffu); }

/// First position in sorted keys[0, n) whose key is not below k.
template <class Keys>
KOKKOS_INLINE_FUNCTION int key_lower_bound(const Keys& keys, int n, std::uint64_t k) {
  int lo = 0, hi = n;
  while (lo < hi) {
    const int mid = (lo + hi) / 2;
    if (keys(mid) < k) lo = mid + 1; else hi = mid;
  }
  return lo;
}

/// bin_sort_keys' scratch, kept between rebuilds so that a sort after the first allocates nothing where the keys
/// have not outgrown it (on a GPU an allocation holds the host until the device is idle).
struct KeySortBuffers {
  IndexView count, fill, offset;  ///< per bin: its keys, those placed so far, its first position
  PairKeyView sorted;
};

/// Sorts contact keys ascending (they are unique, so every method gives the same order): std::sort where the
/// keys live in host memory, bin_sort_keys elsewhere.
void sort_keys(const PairKeyView& keys, KeySortBuffers& kept);

/// A counting sort over bins uniform in hi * span + lo (span: the largest lo + 1), a numbering in the keys' order
/// that is dense wherever the gids are, then each bin's few keys in order. Bins uniform in the raw key (Kokkos::sort's)
/// put all of a wall's contacts in one bin (ball-wall keys are object << 32 | gid), which Kokkos::BinSort orders by
/// a bubble sort in one thread: quadratic in the balls on the wall (0.4 s a rebuild at 53,704 balls on an H100).
void bin_sort_keys(const PairKeyView& keys, KeySortBuffers& kept);

struct ContactList {
  PairKeyView key;
  IndexView i;            ///< local index of particle 1
  IndexView j;            ///< local index of particle 2, or wall object number
  // history (survives rebuilds through history_remap)
  Vec3View fs;            ///< shear force on particle 1 (N)
  Vec3View mr;            ///< rolling moment on particle 1 (N m)
  FlagView flags;
  ScalarView slot[kHistorySlots];  ///< the extensions' scalar history (contact_params.hpp, HistorySlot)
  // results of the current step
  Vec3View fc;            ///< total contact force on particle 1 (N)
  Vec3View mo;            ///< moment on particle 1 (N m), ball-ball: the owner's side, summed in its gather
  Vec3View mt;            ///< moment on the gathering side (N m): particle 2 (ball-ball), the ball (ball-wall)
  ScalarView fn;          ///< linear normal force (N), 0 when not touching
  int n = 0;

  ContactList() = default;
  explicit ContactList(int count);
};

/// What a contact list's rebuild keeps for the next one, so that a rebuild after the first few allocates nothing:
/// the search's counts and offsets, and two sets of the list's arrays with room to spare. The search writes its keys
/// and the remap the new list into the set the present list does not use (both read the present list meanwhile),
/// and the new list then takes that set: a list older than the present one must not be kept past a rebuild.
/// The arrays of 3-vectors of a list made here have more rows than contacts (room_rows); those of one value a row
/// have exactly n.
struct ListBuffers {
  IndexView count, offset;
  KeySortBuffers sort;
  ContactList set[2];
  int next = 0;  ///< the set the next list is written into
};

}  // namespace dem
