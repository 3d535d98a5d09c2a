#pragma once
/// Packs of W doubles, so that one CPU work item evaluates W ball-ball contacts at once. A contact is one long
/// dependent chain (two square roots and several divisions in a row), too long for the out-of-order window to
/// overlap two of them; W lanes of a vector register run W chains side by side, and a vector division or square
/// root costs about what a scalar one does. Every lane does the IEEE operations of the scalar code, so a lane's
/// result is bit for bit the Real one, given that the build fuses no multiply-add (tests/test_simd_lanes.cpp checks it).
///
/// GPUs take one contact per thread (kContactLanes = 1): T is then Real and nothing here is used.
#include "kernels/core/det_math.hpp"
#include "kernels/core/types.hpp"

#include <type_traits>

#if !defined(KOKKOS_ENABLE_CUDA) && !defined(KOKKOS_ENABLE_HIP) && !defined(KOKKOS_ENABLE_SYCL)
#define TRIAXDEM_HOST_PACKS 1
#include <cmath>
#include <cstring>
#if defined(__AVX__)
#include <immintrin.h>
#endif
#endif

namespace dem {

#ifdef TRIAXDEM_HOST_PACKS
/// Contacts per work item of the ball-ball force kernel: one AVX register of doubles.
inline constexpr int kContactLanes = 4;

struct Mask4 {
  typedef long long V __attribute__((vector_size(32)));
  V m;
  friend Mask4 operator&(const Mask4& a, const Mask4& b) { return {a.m & b.m}; }
  friend Mask4 operator|(const Mask4& a, const Mask4& b) { return {a.m | b.m}; }
  friend Mask4 operator!(const Mask4& a) { return {~a.m}; }
  bool operator[](int k) const { return m[k] != 0; }
};
/// Whether any (all) lanes hold: one vptest where AVX is there (or-ing four extracted lanes cost about 45
/// instructions per pack of the force kernel, callgrind).
inline bool any(const Mask4& a) {
#if defined(__AVX__)
  return !_mm256_testz_si256(__m256i(a.m), __m256i(a.m));
#else
  return (a.m[0] | a.m[1] | a.m[2] | a.m[3]) != 0;
#endif
}
inline bool all(const Mask4& a) {
#if defined(__AVX__)
  return _mm256_testc_si256(__m256i(a.m), _mm256_set1_epi64x(-1));
#else
  return (a.m[0] & a.m[1] & a.m[2] & a.m[3]) != 0;
#endif
}

struct Pack4 {
  typedef double V __attribute__((vector_size(32)));
  V v;
  Pack4() : v{0, 0, 0, 0} {}
  Pack4(double s) : v{s, s, s, s} {}  // NOLINT: a Real broadcasts, as in Real arithmetic
  explicit Pack4(V a) : v(a) {}
  double operator[](int k) const { return v[k]; }
  void set(int k, double s) { v[k] = s; }
  Pack4& operator+=(const Pack4& o) { v += o.v; return *this; }
  Pack4& operator-=(const Pack4& o) { v -= o.v; return *this; }
  Pack4& operator*=(const Pack4& o) { v *= o.v; return *this; }
  friend Pack4 operator+(const Pack4& a, const Pack4& b) { return Pack4(a.v + b.v); }
  friend Pack4 operator-(const Pack4& a, const Pack4& b) { return Pack4(a.v - b.v); }
  friend Pack4 operator*(const Pack4& a, const Pack4& b) { return Pack4(a.v * b.v); }
  friend Pack4 operator/(const Pack4& a, const Pack4& b) { return Pack4(a.v / b.v); }
  friend Pack4 operator-(const Pack4& a) { return Pack4(-a.v); }
  friend Mask4 operator<(const Pack4& a, const Pack4& b) { return {a.v < b.v}; }
  friend Mask4 operator<=(const Pack4& a, const Pack4& b) { return {a.v <= b.v}; }
  friend Mask4 operator>(const Pack4& a, const Pack4& b) { return {a.v > b.v}; }
  friend Mask4 operator==(const Pack4& a, const Pack4& b) { return {a.v == b.v}; }
  friend Mask4 operator!=(const Pack4& a, const Pack4& b) { return {a.v != b.v}; }
};
inline Pack4 select(const Mask4& m, const Pack4& a, const Pack4& b) { return Pack4(m.m ? a.v : b.v); }

namespace kc {
inline Pack4 sqrt(const Pack4& a) {
#if defined(__AVX__)
  return Pack4(Pack4::V(_mm256_sqrt_pd(__m256d(a.v))));
#else
  Pack4 r;
  for (int k = 0; k < 4; ++k) r.set(k, std::sqrt(a[k]));
  return r;
#endif
}
inline Pack4 exp(const Pack4& a) {
  Pack4 r;
  for (int k = 0; k < 4; ++k) r.set(k, kc::exp(a[k]));
  return r;
}
/// |a| by clearing the sign bit, as fabs does (-0 gives +0).
inline Pack4 fabs(const Pack4& a) {
  const Mask4::V magnitude = Mask4::V{} + 0x7fffffffffffffffLL;
  return Pack4(Pack4::V(Mask4::V(a.v) & magnitude));
}
/// The scalar shims' operand order (b < a ? b : a), so that equal operands pick the same one.
inline Pack4 min(const Pack4& a, const Pack4& b) { return select(b < a, b, a); }
inline Pack4 max(const Pack4& a, const Pack4& b) { return select(a < b, b, a); }
}  // namespace kc

/// The largest lane. With a NaN lane the result is some lane: good for a filter whose per-lane test ignores NaN.
inline Real max_lane(const Pack4& a) {
  const Real l = a[0] < a[1] ? a[1] : a[0], h = a[2] < a[3] ? a[3] : a[2];
  return l < h ? h : l;
}

/// Lanes a, b, c, d of the eight lanes of x then y, and a pack from four doubles in memory. The two compilers
/// spell a constant shuffle differently (GCC's __builtin_shuffle takes an index vector, clang's
/// __builtin_shufflevector constant arguments); this is the one place that knows.
template <int a, int b, int c, int d>
inline Pack4::V shuffle(const Pack4::V& x, const Pack4::V& y) {
#if defined(__clang__)
  return __builtin_shufflevector(x, y, a, b, c, d);
#else
  return __builtin_shuffle(x, y, Mask4::V{a, b, c, d});
#endif
}
inline Pack4::V load_pack(const double* p) {
  Pack4::V r;
  std::memcpy(&r, p, sizeof(r));
  return r;
}

using ContactPack = Pack4;
#else
inline constexpr int kContactLanes = 1;
using ContactPack = Real;
#endif

/// Contact flag bits (ContactFlag) of the lanes: one byte per contact.
template <class T>
struct LaneFlags {
  using type = std::uint8_t;
};
/// Sets or clears bit in the flags of the lanes where `on` holds.
KOKKOS_INLINE_FUNCTION void set_flag(std::uint8_t& f, bool on, std::uint8_t bit) {
  f = on ? std::uint8_t(f | bit) : std::uint8_t(f & ~bit);
}
/// The flags of a where m holds, of b elsewhere.
KOKKOS_INLINE_FUNCTION std::uint8_t select_flags(bool m, std::uint8_t a, std::uint8_t b) { return m ? a : b; }
#ifdef TRIAXDEM_HOST_PACKS
/// The flag bytes of four contacts, widened to lanes so that setting a bit where a mask holds is one vector op.
struct Flags4 {
  Mask4::V bits = {0, 0, 0, 0};
  std::uint8_t operator[](int k) const { return static_cast<std::uint8_t>(bits[k]); }
};
template <>
struct LaneFlags<Pack4> {
  using type = Flags4;
};
inline void set_flag(Flags4& f, const Mask4& on, std::uint8_t bit) {
  const long long b = bit;
  f.bits = (f.bits & ~b) | (on.m & b);
}
inline void set_flag(Flags4& f, bool on, std::uint8_t bit) { set_flag(f, Mask4{Mask4::V{} - (on ? 1 : 0)}, bit); }
inline Flags4 select_flags(const Mask4& m, const Flags4& a, const Flags4& b) {
  Flags4 out;
  out.bits = (a.bits & m.m) | (b.bits & ~m.m);
  return out;
}
#endif

/// Unrolls a loop over the lanes, so that each lane's index is a constant and its value stays in registers.
#ifdef TRIAXDEM_HOST_PACKS
#define TRIAXDEM_UNROLL_LANES _Pragma("GCC unroll 4")
#else
#define TRIAXDEM_UNROLL_LANES
#endif

/// The pack whose lane k is f(k); for a Real, f(0). The lanes are built in registers: writing them one at a
/// time through a loop index goes through memory, and each pack's load then waits for its four stores.
template <class T, class F>
KOKKOS_INLINE_FUNCTION T from_lanes(const F& f) {
#ifdef TRIAXDEM_HOST_PACKS
  if constexpr (std::is_same<T, Pack4>::value) return Pack4(Pack4::V{f(0), f(1), f(2), f(3)});
  else
#endif
    return f(0);
}

/// Lane k of a pack; a Real is its own lane 0.
KOKKOS_INLINE_FUNCTION Real lane(Real a, int) { return a; }
KOKKOS_INLINE_FUNCTION bool lane(bool m, int) { return m; }
#ifdef TRIAXDEM_HOST_PACKS
inline Real lane(const Pack4& a, int k) { return a[k]; }
inline bool lane(const Mask4& m, int k) { return m[k]; }
inline std::uint8_t lane(const Flags4& f, int k) { return f[k]; }
#endif
KOKKOS_INLINE_FUNCTION std::uint8_t lane(std::uint8_t f, int) { return f; }
KOKKOS_INLINE_FUNCTION Real max_lane(Real a) { return a; }

}  // namespace dem
