#pragma once
/// Reductions whose rounding depends on nothing but the item count: a fixed-shape tree, the same on every backend
/// and thread count. Stage decisions (unbalanced-force ratio) and the servo (contact stress) depend on them, so
/// they must be as repeatable as the state.
///
/// The tree: items in blocks of kReduceBlock; in a block, value k takes value k + h for h = B/2, B/4, .., 1 (the
/// halving tree, past-the-end items as zeros); the block results are items of the next level, until one is left.
/// A GPU reduces a block with a team of B threads in shared memory, a CPU with one thread in a loop: the same
/// operations on the same operands, so the same bits, and every item is computed by its own thread on a GPU.
///
/// Segments (a batch of specimens, each its own range of items) reduce in one launch per level, each segment by the
/// tree it would get alone: its blocks start at its first item, and its root is written at the level where it is
/// one block (SegmentedTree).
#include <utility>
#include <vector>

#include "kernels/core/simd.hpp"
#include "kernels/core/types.hpp"

namespace dem {

constexpr int kReduceBlock = 256;
constexpr std::size_t kGpuSharedPerBlock = 48 * 1024;

/// Device scratch for the tree's block results, of at least `count` Reals: one buffer, grown and never shrunk,
/// so that a step allocates nothing. Kernels run in order, so one reduction's use ends before the next begins.
Kokkos::View<Real*, MemSpace> reduce_scratch(std::size_t count);
/// Device room for one root's values (kMaxReduceValues), apart from the scratch, for reductions whose root the
/// host reads.
constexpr int kMaxReduceValues = 27;  // a specimen's three stress tensors (specimen_stress)
Kokkos::View<Real*, MemSpace> reduce_root();
/// Copies reduce_root's first `count` values to the host's `out`.
void read_root(Real* out, int count);

/// Exclusive scan of counts[0, n) into offsets[0, n] (offsets[n] the total, returned); `counts` may be `offsets`
/// itself, each entry read before it is overwritten. Integer sums: the same for any order.
int exclusive_scan(const char* label, const IndexView& counts, const IndexView& offsets, int n);

/// One block of a level of the tree: its items [begin, end) (end - begin <= kReduceBlock; none gives zeros), and
/// where its values go: slot `out` of the level's results, or, with out < 0, the root of segment -1 - out.
struct ReduceBlock {
  int begin = 0, end = 0, out = 0;
};
using ReduceBlockView = Kokkos::View<ReduceBlock*, MemSpace>;

namespace detail {

using ReduceTeam = Kokkos::TeamPolicy<ExecSpace>::member_type;
using TeamScratch = Kokkos::View<Real*, ExecSpace::scratch_memory_space, Kokkos::MemoryUnmanaged>;

/// Level > 0 of the tree: item i's values are a result of the level below (value q at in[i * NV + q]).
template <int NV>
struct LevelItems {
  const Real* in;
  KOKKOS_INLINE_FUNCTION void operator()(const int i, int, Real (*vals)[NV]) const {
    for (int q = 0; q < NV; ++q) vals[0][q] = in[i * NV + q];
  }
};

/// The blocks of one segment of n items: block b holds items [b B, (b + 1) B), its result goes to slot b, or to the
/// root where it is the level's only block.
struct EvenBlocks {
  int n;
  KOKKOS_INLINE_FUNCTION ReduceBlock operator()(const int b) const {
    const int begin = b * kReduceBlock, end = n - begin < kReduceBlock ? n : begin + kReduceBlock;
    return {begin, end, n <= kReduceBlock ? -1 : b};
  }
};

/// The blocks of a level of a SegmentedTree, listed.
struct ListedBlocks {
  Kokkos::View<const ReduceBlock*, MemSpace> list;
  KOKKOS_INLINE_FUNCTION ReduceBlock operator()(const int b) const { return list(b); }
};

/// One level: team b reduces the items of blocks(b) (W at a time) to its result slot or root, value q at
/// [slot * NV + q].
template <int NSUM, int NMAX, int W, class F, class Blocks>
struct TreeLevel {
  static constexpr int NV = NSUM + NMAX, B = kReduceBlock;
  static_assert(B % W == 0, "a group of W items stays in one block");
  F f;
  Blocks blocks;
  Real* out;
  Real* roots;
  int root_stride;  ///< Reals from one segment's root to the next's
  int scratch_level;

  KOKKOS_INLINE_FUNCTION void operator()(const ReduceTeam& t) const {
    const TeamScratch s(t.team_scratch(scratch_level), NV * B);
    const ReduceBlock blk = blocks(t.league_rank());
    Kokkos::parallel_for(Kokkos::TeamThreadRange(t, B / W), [&](const int g) {
      const int i = blk.begin + g * W;
      const int count = blk.end - i < W ? (blk.end - i > 0 ? blk.end - i : 0) : W;
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
      Real* to = blk.out >= 0 ? out + blk.out * NV : roots + (-1 - blk.out) * root_stride;
      for (int q = 0; q < NV; ++q) to[q] = s(q * B);
    });
  }
};

template <int NSUM, int NMAX, int W, class F, class Blocks>
void tree_level(const char* label, int nblock, const F& f, const Blocks& blocks, Real* out, Real* roots,
                int root_stride = NSUM + NMAX) {
  using Level = TreeLevel<NSUM, NMAX, W, F, Blocks>;
  const std::size_t bytes = TeamScratch::shmem_size(Level::NV * kReduceBlock);
#ifdef TRIAXDEM_HOST_PACKS
  const int team = 1;  // a CPU thread walks its block: teams of threads would only add barriers
  const int level = 0;
#else
  const int team = kReduceBlock / W;
  // A GPU block gets 48 KiB of shared memory unless the kernel opts in to more, which Kokkos 3.4 does not: a block of
  // more values (a specimen's 27 stress sums, 55 KB) goes to the team's scratch in global memory. The same tree and
  // the same operations, so the same bits.
  const int level = bytes > kGpuSharedPerBlock ? 1 : 0;
#endif
  const auto policy = Kokkos::TeamPolicy<ExecSpace>(nblock, team).set_scratch_size(level, Kokkos::PerTeam(bytes));
  Kokkos::parallel_for(label, policy, Level{f, blocks, out, roots, root_stride, level});
}

}  // namespace detail

/// The tree of each of several segments of items, reduced side by side: segment s is items [ranges[s].first,
/// ranges[s].second). The host lays out the levels' blocks from the segments' sizes (plan: a copy to the device, so
/// once per change of sizes, at a rebuild), and each reduction then launches one kernel per level.
class SegmentedTree {
 public:
  /// ranges: each segment's items [first, second), in any order, apart or not.
  void plan(const std::vector<std::pair<int, int>>& ranges);
  int segments() const { return segments_; }
  int levels() const { return static_cast<int>(levels_.size()); }
  /// Level l's blocks, their count, and where its results start in the scratch (slots, each of NV values).
  const ReduceBlockView& blocks(int l) const { return levels_[static_cast<std::size_t>(l)].blocks; }
  int block_count(int l) const { return levels_[static_cast<std::size_t>(l)].count; }
  std::size_t first_slot(int l) const { return levels_[static_cast<std::size_t>(l)].first_slot; }
  /// Result slots of all levels.
  std::size_t slots() const { return slots_; }

 private:
  struct Level {
    ReduceBlockView blocks;
    int count = 0;
    std::size_t first_slot = 0;
  };
  std::vector<Level> levels_;
  int segments_ = 0;
  std::size_t slots_ = 0;
};

/// Reduces f's values over each segment of `tree` as deterministic_reduce_lanes_to does over one range of items:
/// segment s's root, bit for bit the one it would get alone, goes to roots[s * stride + q] (stride 0: NSUM + NMAX),
/// in device memory. f(i, count, vals) is called with i the item's index among all the segments' items.
template <int NSUM, int NMAX, int W, class F>
void segmented_reduce_lanes_to(const char* label, const SegmentedTree& tree, const F& f, Real* roots, int stride = 0) {
  constexpr int NV = NSUM + NMAX;
  if (stride == 0) stride = NV;
  Real* scratch = tree.slots() > 0 ? reduce_scratch(tree.slots() * NV).data() : nullptr;
  for (int l = 0; l < tree.levels(); ++l) {
    Real* out = scratch + tree.first_slot(l) * NV;
    const detail::ListedBlocks blocks{tree.blocks(l)};
    if (l == 0) {
      detail::tree_level<NSUM, NMAX, W>(label, tree.block_count(l), f, blocks, out, roots, stride);
    } else {
      const Real* in = scratch + tree.first_slot(l - 1) * NV;
      detail::tree_level<NSUM, NMAX, 1>(label, tree.block_count(l), detail::LevelItems<NV>{in}, blocks, out, roots,
                                        stride);
    }
  }
}

/// Reduces the values f(i, count, vals) of items [0, n), W at a time: vals[k] gets item i + k's values, k < count
/// <= W; vals[.][0, NSUM) are summed and vals[.][NSUM, NSUM + NMAX) maximised (from 0: non-negative quantities).
/// The tree of the header; its root's NSUM + NMAX values go to `root`, in device memory, and the host waits for
/// nothing: a step's statistics stay on the device until the host reads them (host/engine/step_rows.hpp).
template <int NSUM, int NMAX, int W, class F>
void deterministic_reduce_lanes_to(const char* label, int n, const F& f, Real* root) {
  constexpr int NV = NSUM + NMAX;
  const auto blocks = [](int items) { return (items + kReduceBlock - 1) / kReduceBlock; };
  if (n <= 0) {  // one block of no items: zeros
    detail::tree_level<NSUM, NMAX, W>(label, 1, f, detail::EvenBlocks{0}, nullptr, root);
    return;
  }
  std::size_t total = 0;  // the levels below the root
  for (int m = blocks(n); m > 1; m = blocks(m)) total += static_cast<std::size_t>(m) * NV;
  Real* level = total > 0 ? reduce_scratch(total).data() : nullptr;
  int m = blocks(n);
  detail::tree_level<NSUM, NMAX, W>(label, m, f, detail::EvenBlocks{n}, level, root);
  while (m > 1) {
    const int up = blocks(m);
    Real* next = level + static_cast<std::size_t>(m) * NV;
    detail::tree_level<NSUM, NMAX, 1>(label, up, detail::LevelItems<NV>{level}, detail::EvenBlocks{m}, next, root);
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
