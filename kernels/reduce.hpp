#pragma once
/// Reductions whose rounding does not depend on the thread count: fixed-size blocks reduced in order,
/// then the block results combined in order on the host. Stage decisions (unbalanced-force ratio)
/// depend on them, so they must be as repeatable as the state.
#include "types.hpp"

#include <string>

namespace dem {

constexpr int kReduceBlock = 512;

/// Block b of a reduction over i in [0, n): f(i, count, vals) fills vals[k] for item i + k, k < count <= W (W items
/// at once, as lanes), and the items' values are taken in order: vals[.][0, NSUM) summed, vals[.][NSUM, NSUM + NMAX)
/// maximised (from 0, so for non-negative quantities). The block's results go to part(b, .).
template <int NSUM, int NMAX, int W, class F, class Part>
KOKKOS_INLINE_FUNCTION void reduce_block(int b, int n, const F& f, const Part& part) {
  static_assert(kReduceBlock % W == 0, "a group of W items stays in one block");
  constexpr int NV = NSUM + NMAX;
  Real acc[NV] = {};
  const int end = (b + 1) * kReduceBlock < n ? (b + 1) * kReduceBlock : n;
  for (int i = b * kReduceBlock; i < end; i += W) {
    const int count = end - i < W ? end - i : W;
    Real v[W][NV] = {};
    f(i, count, v);
    for (int k = 0; k < count; ++k) {
      for (int q = 0; q < NSUM; ++q) acc[q] += v[k][q];
      for (int q = NSUM; q < NV; ++q) acc[q] = v[k][q] > acc[q] ? v[k][q] : acc[q];
    }
  }
  for (int q = 0; q < NV; ++q) part(b, q) = acc[q];
}

/// Reduces the values f(i, count, vals) of items [0, n), W at a time (reduce_block): fixed-size blocks in parallel,
/// then the block results in block order on the host.
template <int NSUM, int NMAX, int W, class F>
void deterministic_reduce_lanes(const char* label, int n, const F& f, Real (&out)[NSUM + NMAX]) {
  constexpr int NV = NSUM + NMAX;
  const int nblock = (n + kReduceBlock - 1) / kReduceBlock;
  // Every entry is written by its block: no zero-fill kernel ahead of the reduction, which runs every step.
  Kokkos::View<Real**, Layout, MemSpace> part(Kokkos::view_alloc(Kokkos::WithoutInitializing, std::string(label)),
                                              nblock, NV);
  Kokkos::parallel_for(label, RangePolicy(0, nblock),
                       KOKKOS_LAMBDA(const int b) { reduce_block<NSUM, NMAX, W>(b, n, f, part); });
  auto h = Kokkos::create_mirror_view_and_copy(HostSpace(), part);
  for (int q = 0; q < NV; ++q) out[q] = 0;
  for (int b = 0; b < nblock; ++b) {
    for (int q = 0; q < NSUM; ++q) out[q] += h(b, q);
    for (int q = NSUM; q < NV; ++q) out[q] = h(b, q) > out[q] ? h(b, q) : out[q];
  }
}

/// An item function f(i, vals) as one of W = 1 item at a time.
template <class F, int NV>
struct OneAtATime {
  F f;
  KOKKOS_INLINE_FUNCTION void operator()(const int i, int, Real (*vals)[NV]) const { f(i, vals[0]); }
};

/// Reduces values produced by f(i, vals) over i in [0, n): vals[0, NSUM) are summed, vals[NSUM, NSUM +
/// NMAX) are maximised (they start at 0, so use them for non-negative quantities).
template <int NSUM, int NMAX, class F>
void deterministic_reduce(const char* label, int n, const F& f, Real (&out)[NSUM + NMAX]) {
  deterministic_reduce_lanes<NSUM, NMAX, 1>(label, n, OneAtATime<F, NSUM + NMAX>{f}, out);
}

}  // namespace dem
