#pragma once
/// Scratch kept between rebuilds, so that a rebuild after the first allocates nothing where it can: on a GPU an
/// allocation and its free each hold the host until the device is idle.
#include <cstddef>
#include <string>
#include <utility>

#include "kernels/core/types.hpp"

namespace dem {

/// The first n entries of a rank-1 buffer kept by the caller: grown to a quarter more than asked when too short,
/// never shrunk. The entries hold what was there before: zero them where needed.
template <class View>
View room(View& buffer, std::size_t n, const char* label) {
  static_assert(View::rank == 1, "a rank-1 buffer: a range of its entries is a View of the same layout");
  if (buffer.extent(0) < n) buffer = View(Kokkos::view_alloc(Kokkos::WithoutInitializing, std::string(label)), n + n / 4 + 16);
  return Kokkos::subview(buffer, std::make_pair(std::size_t(0), n));
}

/// A buffer of fixed extents past the first (as Vec3View) with at least n rows, grown as room grows, and returned
/// whole: a range of rows of a LayoutLeft View (a GPU's) is not a View of the same layout. Rows n and after are
/// spare room.
template <class View>
View room_rows(View& buffer, std::size_t n, const char* label) {
  static_assert(View::rank == 2, "a buffer of rows");
  if (buffer.extent(0) < n) buffer = View(Kokkos::view_alloc(Kokkos::WithoutInitializing, std::string(label)), n + n / 4 + 16);
  return buffer;
}

/// `kept`, of exactly n rows: reallocated only where its row count differs (any rank; a View of fixed extents past
/// the first, as Vec3View).
template <class View>
View same_size(View& kept, std::size_t n, const char* label) {
  if (kept.extent(0) != n) kept = View(Kokkos::view_alloc(Kokkos::WithoutInitializing, std::string(label)), n);
  return kept;
}

/// A host View of `v`'s extents kept by the caller, to fill and copy to v: v itself where the host can reach it (as
/// Kokkos::create_mirror_view), else `kept`, made again only where v's extents differ from it.
template <class View>
typename View::HostMirror kept_mirror(typename View::HostMirror& kept, const View& v) {
  if (Kokkos::SpaceAccessibility<HostSpace, typename View::memory_space>::accessible)
    return Kokkos::create_mirror_view(v);
  bool same = kept.data() != nullptr || v.size() == 0;
  for (unsigned r = 0; r < View::rank; ++r) same = same && kept.extent(r) == v.extent(r);
  if (!same) kept = Kokkos::create_mirror(v);
  return kept;
}

/// What `v` holds, readable on the host, in kept_mirror's View (as Kokkos::create_mirror_view_and_copy).
template <class View>
typename View::HostMirror kept_host_copy(typename View::HostMirror& kept, const View& v) {
  const typename View::HostMirror h = kept_mirror(kept, v);
  if (!Kokkos::SpaceAccessibility<HostSpace, typename View::memory_space>::accessible) Kokkos::deep_copy(h, v);
  return h;
}

/// Sets a rank-1 View's entries to zero in a kernel (a deep_copy of a value waits for the device).
template <class View>
void zero(const View& v, const char* label) {
  Kokkos::parallel_for(label, RangePolicy(0, static_cast<int>(v.extent(0))), KOKKOS_LAMBDA(const int i) { v(i) = 0; });
}

}  // namespace dem
