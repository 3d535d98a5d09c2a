#pragma once
/// Small device-callable 3-vector and the math shim that compiles on Kokkos 3.4 and 4.x
/// (Kokkos::sqrt/min/max appeared in 3.7; 4.0 dropped Kokkos::Experimental math).
#include "types.hpp"

namespace dem {
namespace kc {
#if KOKKOS_VERSION >= 30700
using Kokkos::exp;
using Kokkos::fabs;
using Kokkos::floor;
using Kokkos::isfinite;
using Kokkos::max;
using Kokkos::min;
using Kokkos::sqrt;
#else
using Kokkos::Experimental::exp;
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

struct Vec3 {
  Real x = 0, y = 0, z = 0;
  KOKKOS_INLINE_FUNCTION Vec3() = default;
  KOKKOS_INLINE_FUNCTION Vec3(Real a, Real b, Real c) : x(a), y(b), z(c) {}
  KOKKOS_INLINE_FUNCTION Real operator[](int d) const { return d == 0 ? x : (d == 1 ? y : z); }
  KOKKOS_INLINE_FUNCTION Vec3& operator+=(const Vec3& o) { x += o.x; y += o.y; z += o.z; return *this; }
  KOKKOS_INLINE_FUNCTION Vec3& operator-=(const Vec3& o) { x -= o.x; y -= o.y; z -= o.z; return *this; }
  KOKKOS_INLINE_FUNCTION Vec3& operator*=(Real s) { x *= s; y *= s; z *= s; return *this; }
};
KOKKOS_INLINE_FUNCTION Vec3 operator+(Vec3 a, const Vec3& b) { return a += b; }
KOKKOS_INLINE_FUNCTION Vec3 operator-(Vec3 a, const Vec3& b) { return a -= b; }
KOKKOS_INLINE_FUNCTION Vec3 operator-(const Vec3& a) { return Vec3(-a.x, -a.y, -a.z); }
KOKKOS_INLINE_FUNCTION Vec3 operator*(Real s, Vec3 a) { return a *= s; }
KOKKOS_INLINE_FUNCTION Vec3 operator*(Vec3 a, Real s) { return a *= s; }
KOKKOS_INLINE_FUNCTION Real dot(const Vec3& a, const Vec3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
KOKKOS_INLINE_FUNCTION Vec3 cross(const Vec3& a, const Vec3& b) {
  return Vec3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
KOKKOS_INLINE_FUNCTION Real norm2(const Vec3& a) { return dot(a, a); }
KOKKOS_INLINE_FUNCTION Real norm(const Vec3& a) { return kc::sqrt(dot(a, a)); }

/// Read/write row i of a 3-vector View.
template <class V>
KOKKOS_INLINE_FUNCTION Vec3 load(const V& v, int i) { return Vec3(v(i, 0), v(i, 1), v(i, 2)); }
template <class V>
KOKKOS_INLINE_FUNCTION void store(const V& v, int i, const Vec3& a) { v(i, 0) = a.x; v(i, 1) = a.y; v(i, 2) = a.z; }

/// The tangential part of a relative to the unit normal n.
KOKKOS_INLINE_FUNCTION Vec3 tangential(const Vec3& a, const Vec3& n) { return a - dot(a, n) * n; }

/// Carries a stored tangential vector (shear force, rolling moment) into the current contact plane,
/// keeping its magnitude (the contact frame turned, the spring did not relax).
KOKKOS_INLINE_FUNCTION Vec3 rotate_into_plane(const Vec3& s, const Vec3& n) {
  const Real m2 = norm2(s);
  if (m2 == Real(0)) return s;
  Vec3 t = tangential(s, n);
  const Real t2 = norm2(t);
  if (t2 == Real(0)) return Vec3();
  return t * kc::sqrt(m2 / t2);
}

}  // namespace dem
