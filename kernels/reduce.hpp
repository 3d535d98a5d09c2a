#pragma once
/// Reductions whose rounding does not depend on the thread count: fixed-size blocks reduced in order,
/// then the block results combined in order on the host. Stage decisions (unbalanced-force ratio)
/// depend on them, so they must be as repeatable as the state.
#include "types.hpp"

#include <string>

namespace dem {

constexpr int kReduceBlock = 512;

/// Reduces values produced by f(i, vals) over i in [0, n): vals[0, NSUM) are summed, vals[NSUM, NSUM +
/// NMAX) are maximised (they start at 0, so use them for non-negative quantities).
template <int NSUM, int NMAX, class F>
void deterministic_reduce(const char* label, int n, const F& f, Real (&out)[NSUM + NMAX]) {
  constexpr int NV = NSUM + NMAX;
  const int nblock = (n + kReduceBlock - 1) / kReduceBlock;
  Kokkos::View<Real**, Layout, MemSpace> part(std::string(label), nblock, NV);
  Kokkos::parallel_for(label, RangePolicy(0, nblock), KOKKOS_LAMBDA(const int b) {
    Real acc[NV] = {};
    const int end = (b + 1) * kReduceBlock < n ? (b + 1) * kReduceBlock : n;
    for (int i = b * kReduceBlock; i < end; ++i) {
      Real v[NV] = {};
      f(i, v);
      for (int q = 0; q < NSUM; ++q) acc[q] += v[q];
      for (int q = NSUM; q < NV; ++q) acc[q] = v[q] > acc[q] ? v[q] : acc[q];
    }
    for (int q = 0; q < NV; ++q) part(b, q) = acc[q];
  });
  auto h = Kokkos::create_mirror_view_and_copy(HostSpace(), part);
  for (int q = 0; q < NV; ++q) out[q] = 0;
  for (int b = 0; b < nblock; ++b) {
    for (int q = 0; q < NSUM; ++q) out[q] += h(b, q);
    for (int q = NSUM; q < NV; ++q) out[q] = h(b, q) > out[q] ? h(b, q) : out[q];
  }
}

}  // namespace dem
