#pragma once
/// Sums whose rounding does not depend on the thread count: fixed-size blocks summed in order, then
/// the block sums added in order on the host. Stage decisions (unbalanced-force ratio) depend on them.
#include "types.hpp"

#include <string>

namespace dem {

constexpr int kReduceBlock = 512;

/// Sums nvals values produced by f(i, vals) (vals: Real[nvals]) over i in [0, n), deterministically.
template <int NVALS, class F>
void deterministic_sum(const char* label, int n, const F& f, Real (&out)[NVALS]) {
  const int nblock = (n + kReduceBlock - 1) / kReduceBlock;
  Kokkos::View<Real**, Layout, MemSpace> part(std::string(label), nblock, NVALS);
  Kokkos::parallel_for(label, RangePolicy(0, nblock), KOKKOS_LAMBDA(const int b) {
    Real acc[NVALS] = {};
    const int end = (b + 1) * kReduceBlock < n ? (b + 1) * kReduceBlock : n;
    for (int i = b * kReduceBlock; i < end; ++i) {
      Real v[NVALS] = {};
      f(i, v);
      for (int q = 0; q < NVALS; ++q) acc[q] += v[q];
    }
    for (int q = 0; q < NVALS; ++q) part(b, q) = acc[q];
  });
  auto h = Kokkos::create_mirror_view_and_copy(HostSpace(), part);
  for (int q = 0; q < NVALS; ++q) out[q] = 0;
  for (int b = 0; b < nblock; ++b)
    for (int q = 0; q < NVALS; ++q) out[q] += h(b, q);
}

}  // namespace dem
