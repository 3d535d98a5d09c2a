#pragma once
/// Reductions whose rounding depends on nothing but the item count: a fixed-shape tree, the same on every backend
/// and thread count. Stage decisions (unbalanced-force ratio) and the servo (contact stress) depend on them, so
/// they must be as repeatable as the state.
///
/// The tree: items in blocks of kReduceBlock; in a block, value k takes value k + h for h = B/2, B/4, .., 1 (the
/// halving tree, past-the-end items as zeros); the block results are items of the next level, until one is left.
/// A GPU reduces a block with a team of B threads in shared memory, a CPU with one thread in a loop: the same
/// operations on the same operands, so the same bits, and every item is computed by its own thread on a GPU.
#include "kernels/core/simd.hpp"
#include "kernels/core/types.hpp"

namespace dem {

constexpr int kReduceBlock = 256;

/// Device scratch for the tree's block results, of at least `count` Reals: one buffer, grown and never shrunk,
/// so that a step allocates nothing. Kernels run in order, so one reduction's use ends before the next begins.
Kokkos::View<Real*, MemSpace> reduce_scratch(std::size_t count);
/// Device room for one root's values (kMaxReduceValues), apart from the scratch, for reductions whose root the
/// host reads.
constexpr int kMaxReduceValues = 16;
Kokkos::View<Real*, MemSpace> reduce_root();
/// Copies reduce_root's first `count` values to the host's `out`.
void read_root(Real* out, int count);

/// Exclusive scan of counts[0, n) into offsets[0, n] (offsets[n] the total, returned); `counts` may be `offsets`
/// itself, each entry read before it is overwritten. Integer sums: the same for any order.
int exclusive_scan(const char* label, const IndexView& counts, const IndexView& offsets, int n);

namespace detail {

using ReduceTeam = Kokkos::TeamPolicy<ExecSpace>::member_type;
using TeamScratch = Kokkos::View<Real*, ExecSpace::scratch_memory_space, Kokkos::MemoryUnmanaged>;

/// Level > 0 of the tree: item i's values are block i's results of the level below (value q at in[q * n + i]).
template <int NV>
struct LevelItems {
  const Real* in;
  int n;
  KOKKOS_INLINE_FUNCTION void operator()(const int i, int, Real (*vals)[NV]) const {
    for (int q = 0; q < NV; ++q) vals[0][q] = in[q * n + i];
  }
};

/// One level: team b reduces items [b B, (b + 1) B) of f (W at a time) to out[q * nblock + b].
template <int NSUM, int NMAX, int W, class F>
struct TreeLevel {
  static constexpr int NV = NSUM + NMAX, B = kReduceBlock;
  static_assert(B % W == 0, "a group of W items stays in one block");
  F f;
  int n, nblock;
  Real* out;

  KOKKOS_INLINE_FUNCTION void operator()(const ReduceTeam& t) const {
    const TeamScratch s(t.team_scratch(0), NV * B);
    const int base = t.league_rank() * B;
    Kokkos::parallel_for(Kokkos::TeamThreadRange(t, B / W), [&](const int g) {
      const int i = base + g * W;
      const int count = n - i < W ? (n - i > 0 ? n - i : 0) : W;
      Real v[W][NV] = {};
      if (count > 0) f(i, count, v);
      for (int k = 0; k < W; ++k)
        for (int q = 0; q < NV; ++q) s(q * B + g * W + k) = v[k][q];
    });
    t.team_barrier();
    for (int h = B / 2; h >= 1; h /= 2) {
#ifdef TRIAXDEM_HOST_PACKS
      // One thread per team (tree_level): the same operations, each value's row as one loop the compiler vectorises.
      Real* r = s.data();
      for (int q = 0; q < NSUM; ++q)
        for (int k = 0; k < h; ++k) r[q * B + k] += r[q * B + k + h];
      for (int q = NSUM; q < NV; ++q)
        for (int k = 0; k < h; ++k) r[q * B + k] = r[q * B + k + h] > r[q * B + k] ? r[q * B + k + h] : r[q * B + k];
#else
      Kokkos::parallel_for(Kokkos::TeamThreadRange(t, h), [&](const int k) {
        for (int q = 0; q < NSUM; ++q) s(q * B + k) += s(q * B + k + h);
        for (int q = NSUM; q < NV; ++q) s(q * B + k) = s(q * B + k + h) > s(q * B + k) ? s(q * B + k + h) : s(q * B + k);
      });
      t.team_barrier();
#endif
    }
    Kokkos::single(Kokkos::PerTeam(t), [&]() {
      for (int q = 0; q < NV; ++q) out[q * nblock + t.league_rank()] = s(q * B);
    });
  }
};

template <int NSUM, int NMAX, int W, class F>
void tree_level(const char* label, int n, const F& f, Real* out) {
  using Level = TreeLevel<NSUM, NMAX, W, F>;
  const int nblock = (n + kReduceBlock - 1) / kReduceBlock;
#ifdef TRIAXDEM_HOST_PACKS
  const int team = 1;  // a CPU thread walks its block: teams of threads would only add barriers
#else
  const int team = kReduceBlock / W;
#endif
  const auto policy = Kokkos::TeamPolicy<ExecSpace>(nblock, team)
                          .set_scratch_size(0, Kokkos::PerTeam(TeamScratch::shmem_size(Level::NV * kReduceBlock)));
  Kokkos::parallel_for(label, policy, Level{f, n, nblock, out});
}

}  // namespace detail

/// Reduces the values f(i, count, vals) of items [0, n), W at a time: vals[k] gets item i + k's values, k < count
/// <= W; vals[.][0, NSUM) are summed and vals[.][NSUM, NSUM + NMAX) maximised (from 0: non-negative quantities).
/// The tree of the header; its root's NSUM + NMAX values go to `root`, in device memory, and the host waits for
/// nothing: a step's statistics stay on the device until the host reads them (host/engine/step_rows.hpp).
template <int NSUM, int NMAX, int W, class F>
void deterministic_reduce_lanes_to(const char* label, int n, const F& f, Real* root) {
  constexpr int NV = NSUM + NMAX;
  if (n <= 0) {
    Kokkos::parallel_for(label, RangePolicy(0, NV), KOKKOS_LAMBDA(const int q) { root[q] = 0; });
    return;
  }
  const auto blocks = [](int items) { return (items + kReduceBlock - 1) / kReduceBlock; };
  std::size_t total = 0;  // the levels below the root
  for (int m = blocks(n); m > 1; m = blocks(m)) total += static_cast<std::size_t>(m) * NV;
  Real* level = total > 0 ? reduce_scratch(total).data() : nullptr;
  int m = blocks(n);
  detail::tree_level<NSUM, NMAX, W>(label, n, f, m == 1 ? root : level);
  while (m > 1) {
    const int up = blocks(m);
    Real* next = up == 1 ? root : level + static_cast<std::size_t>(m) * NV;
    detail::tree_level<NSUM, NMAX, 1>(label, m, detail::LevelItems<NV>{level, m}, next);
    level = next;
    m = up;
  }
}

/// The same, with the root's values copied to the host's `out`.
template <int NSUM, int NMAX, int W, class F>
void deterministic_reduce_lanes(const char* label, int n, const F& f, Real (&out)[NSUM + NMAX]) {
  constexpr int NV = NSUM + NMAX;
  static_assert(NV <= kMaxReduceValues, "reduce_root holds kMaxReduceValues values");
  deterministic_reduce_lanes_to<NSUM, NMAX, W>(label, n, f, reduce_root().data());
  read_root(out, NV);
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

/// The same, with the root's values left in device memory at `root`.
template <int NSUM, int NMAX, class F>
void deterministic_reduce_to(const char* label, int n, const F& f, Real* root) {
  deterministic_reduce_lanes_to<NSUM, NMAX, 1>(label, n, OneAtATime<F, NSUM + NMAX>{f}, root);
}

}  // namespace dem
