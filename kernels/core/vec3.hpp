#pragma once
/// Small device-callable 3-vector and the math shim that compiles on Kokkos 3.4 and 4.x
/// (Kokkos::sqrt/min/max appeared in 3.7; 4.0 dropped Kokkos::Experimental math).
#include <cstddef>
#include <cstring>
#include <type_traits>

#include "kernels/core/det_math.hpp"
#include "kernels/core/simd.hpp"
#include "kernels/core/types.hpp"

namespace dem {
namespace kc {
// exp is det_math.hpp's: the same bits on every backend.
#if KOKKOS_VERSION >= 30700
using Kokkos::fabs;
using Kokkos::floor;
using Kokkos::isfinite;
using Kokkos::max;
using Kokkos::min;
using Kokkos::sqrt;
#else
using Kokkos::Experimental::fabs;
using Kokkos::Experimental::floor;
using Kokkos::Experimental::isfinite;
using Kokkos::Experimental::sqrt;
template <class T>
KOKKOS_INLINE_FUNCTION constexpr const T& min(const T& a, const T& b) { return b < a ? b : a; }
template <class T>
KOKKOS_INLINE_FUNCTION constexpr const T& max(const T& a, const T& b) { return a < b ? b : a; }
#endif
}  // namespace kc

/// A 3-vector of T: Real for particles, walls and host code, a Pack (simd.hpp) where W contacts are evaluated at
/// once. The operators are hidden friends, so a Real or an int converts to T as it would for a plain function.
template <class T>
struct Vec3T {
  T x = 0, y = 0, z = 0;
  Vec3T() = default;
  KOKKOS_INLINE_FUNCTION Vec3T(const T& a, const T& b, const T& c) : x(a), y(b), z(c) {}
  KOKKOS_INLINE_FUNCTION T operator[](int d) const { return d == 0 ? x : (d == 1 ? y : z); }
  KOKKOS_INLINE_FUNCTION Vec3T& operator+=(const Vec3T& o) { x += o.x; y += o.y; z += o.z; return *this; }
  KOKKOS_INLINE_FUNCTION Vec3T& operator-=(const Vec3T& o) { x -= o.x; y -= o.y; z -= o.z; return *this; }
  KOKKOS_INLINE_FUNCTION Vec3T& operator*=(const T& s) { x *= s; y *= s; z *= s; return *this; }
  friend KOKKOS_INLINE_FUNCTION Vec3T operator+(Vec3T a, const Vec3T& b) { return a += b; }
  friend KOKKOS_INLINE_FUNCTION Vec3T operator-(Vec3T a, const Vec3T& b) { return a -= b; }
  friend KOKKOS_INLINE_FUNCTION Vec3T operator-(const Vec3T& a) { return Vec3T(-a.x, -a.y, -a.z); }
  friend KOKKOS_INLINE_FUNCTION Vec3T operator*(const T& s, Vec3T a) { return a *= s; }
  friend KOKKOS_INLINE_FUNCTION Vec3T operator*(Vec3T a, const T& s) { return a *= s; }
};
using Vec3 = Vec3T<Real>;

template <class T>
KOKKOS_INLINE_FUNCTION T dot(const Vec3T<T>& a, const Vec3T<T>& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
template <class T>
KOKKOS_INLINE_FUNCTION Vec3T<T> cross(const Vec3T<T>& a, const Vec3T<T>& b) {
  return Vec3T<T>(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
template <class T>
KOKKOS_INLINE_FUNCTION T norm2(const Vec3T<T>& a) { return dot(a, a); }
template <class T>
KOKKOS_INLINE_FUNCTION T norm(const Vec3T<T>& a) { return kc::sqrt(dot(a, a)); }

/// Whether a 3-vector View's rows are 3 consecutive Reals (LayoutRight: the host's Vec3View; no View here is
/// allocated with padding). Row i then starts at data() + 3 i, where v(i, d) multiplies i by the View's run-time
/// stride: that address arithmetic was 15% of the contact kernel's instructions (callgrind).
template <class V>
KOKKOS_INLINE_FUNCTION constexpr bool packed_rows() {
  return std::is_same<typename V::array_layout, Kokkos::LayoutRight>::value &&
         std::is_same<typename V::non_const_data_type, Real* [3]>::value;
}

/// Read/write row i of a 3-vector View.
template <class V>
KOKKOS_INLINE_FUNCTION Vec3 load(const V& v, int i) {
  if constexpr (packed_rows<V>()) {
    const Real* r = v.data() + 3 * static_cast<std::ptrdiff_t>(i);
    return Vec3(r[0], r[1], r[2]);
  } else {
    return Vec3(v(i, 0), v(i, 1), v(i, 2));
  }
}
template <class V>
KOKKOS_INLINE_FUNCTION void store(const V& v, int i, const Vec3& a) {
  if constexpr (packed_rows<V>()) {
    Real* r = v.data() + 3 * static_cast<std::ptrdiff_t>(i);
    r[0] = a.x; r[1] = a.y; r[2] = a.z;
  } else {
    v(i, 0) = a.x; v(i, 1) = a.y; v(i, 2) = a.z;
  }
}

/// Lane-wise choice for masks of T: a plain conditional for Real (simd.hpp overloads it for packs).
KOKKOS_INLINE_FUNCTION Real select(bool m, Real a, Real b) { return m ? a : b; }
KOKKOS_INLINE_FUNCTION bool any(bool m) { return m; }
KOKKOS_INLINE_FUNCTION bool all(bool m) { return m; }
template <class M, class T>
KOKKOS_INLINE_FUNCTION Vec3T<T> select(const M& m, const Vec3T<T>& a, const Vec3T<T>& b) {
  return Vec3T<T>(select(m, a.x, b.x), select(m, a.y, b.y), select(m, a.z, b.z));
}

/// The 3-vectors f(0) .. f(W-1) as a vector of lanes.
template <class T, class F>
KOKKOS_INLINE_FUNCTION Vec3T<T> vec_of_lanes(const F& f) {
  Vec3 a[kContactLanes];
  TRIAXDEM_UNROLL_LANES
  for (int k = 0; k < kContactLanes; ++k) a[k] = f(k);
  return Vec3T<T>(from_lanes<T>([&](int k) { return a[k].x; }), from_lanes<T>([&](int k) { return a[k].y; }),
                  from_lanes<T>([&](int k) { return a[k].z; }));
}

/// A Real 3-vector in every lane.
template <class T>
KOKKOS_INLINE_FUNCTION Vec3T<T> broadcast(const Vec3& a) { return Vec3T<T>(T(a.x), T(a.y), T(a.z)); }

/// Lane k of a vector of packs (simd.hpp).
template <class T>
KOKKOS_INLINE_FUNCTION Vec3 lane(const Vec3T<T>& a, int k) { return Vec3(lane(a.x, k), lane(a.y, k), lane(a.z, k)); }

/// Rows s0 .. s0 + W - 1 of a 3-vector View as the lanes of a vector, and back. On the host the rows of a
/// LayoutRight View are 3W consecutive doubles: W = 4 rows are three vector loads or stores and a transpose in
/// registers, where lane by lane they were 12 scalar loads or stores and the inserts or extracts between.
template <class T, class V>
KOKKOS_INLINE_FUNCTION Vec3T<T> load_rows(const V& v, int s0) {
#ifdef TRIAXDEM_HOST_PACKS
  if constexpr (std::is_same<T, Pack4>::value) {
    static_assert(std::is_same<typename V::array_layout, Kokkos::LayoutRight>::value, "rows must be contiguous");
    const Real* a = &v(s0, 0);
    // (x0 y0 z0 x1) (y1 z1 x2 y2) (z2 x3 y3 z3)
    const Pack4::V r0 = load_pack(a), r1 = load_pack(a + 4), r2 = load_pack(a + 8);
    return Vec3T<T>(Pack4(shuffle<0, 1, 2, 5>(shuffle<0, 3, 6, 0>(r0, r1), r2)),
                    Pack4(shuffle<0, 1, 2, 6>(shuffle<1, 4, 7, 0>(r0, r1), r2)),
                    Pack4(shuffle<0, 1, 4, 7>(shuffle<2, 5, 0, 0>(r0, r1), r2)));
  } else
#endif
    return load(v, s0);
}
template <class T, class V>
KOKKOS_INLINE_FUNCTION void store_rows(const V& v, int s0, const Vec3T<T>& a) {
#ifdef TRIAXDEM_HOST_PACKS
  if constexpr (std::is_same<T, Pack4>::value) {
    static_assert(std::is_same<typename V::array_layout, Kokkos::LayoutRight>::value, "rows must be contiguous");
    const Pack4::V x = a.x.v, y = a.y.v, z = a.z.v;
    const Pack4::V r[3] = {shuffle<0, 1, 4, 3>(shuffle<0, 4, 0, 1>(x, y), z),
                           shuffle<0, 1, 6, 3>(shuffle<1, 5, 0, 2>(y, z), x),
                           shuffle<0, 1, 7, 3>(shuffle<2, 7, 0, 3>(z, x), y)};
    std::memcpy(&v(s0, 0), r, sizeof(r));
  } else
#endif
    store(v, s0, a);
}

/// Rows ids[0 .. W) of a 3-vector View as the lanes of a vector: whole rows (load_rows) when the pack is full, its
/// rows then being s0 .. s0 + W - 1, else row by row. The load side of put() below.
template <class T, class V>
KOKKOS_INLINE_FUNCTION Vec3T<T> load_lanes(const V& v, int s0, const int* ids, bool full) {
  return full ? load_rows<T>(v, s0) : vec_of_lanes<T>([&](int k) { return load(v, ids[k]); });
}

/// Where a pack's results go: lane k into row s (LaneRow), or every lane of a full pack into rows s0 .. s0 + W - 1
/// (PackRows, store_rows). One store function serves both (store_law in contact_force.hpp, the leapfrog).
struct LaneRow {
  int s, k;
};
struct PackRows {
  int s0;
};
template <class V, class T>
KOKKOS_INLINE_FUNCTION void put(const V& v, LaneRow at, const Vec3T<T>& a) { store(v, at.s, lane(a, at.k)); }
template <class V, class T>
KOKKOS_INLINE_FUNCTION void put(const V& v, PackRows at, const Vec3T<T>& a) { store_rows(v, at.s0, a); }
template <class V, class T>
KOKKOS_INLINE_FUNCTION void put_scalar(const V& v, LaneRow at, const T& a) { v(at.s) = lane(a, at.k); }
template <class V, class T>
KOKKOS_INLINE_FUNCTION void put_scalar(const V& v, PackRows at, const T& a) {
  TRIAXDEM_UNROLL_LANES
  for (int k = 0; k < kContactLanes; ++k) v(at.s0 + k) = lane(a, k);
}

/// The tangential part of a relative to the unit normal n.
template <class T>
KOKKOS_INLINE_FUNCTION Vec3T<T> tangential(const Vec3T<T>& a, const Vec3T<T>& n) { return a - dot(a, n) * n; }

/// Carries a stored tangential vector (shear force, rolling moment) into the current contact plane,
/// keeping its magnitude (the contact frame turned, the spring did not relax). A zero vector stays zero, and so
/// does one along n. Written with select, not branches, so that W lanes take it together.
template <class T>
KOKKOS_INLINE_FUNCTION Vec3T<T> rotate_into_plane(const Vec3T<T>& s, const Vec3T<T>& n) {
  const T m2 = norm2(s);
  const Vec3T<T> t = tangential(s, n);
  const T t2 = norm2(t);
  return select(m2 == T(0), s, select(t2 == T(0), Vec3T<T>(), t * kc::sqrt(m2 / t2)));
}

}  // namespace dem
