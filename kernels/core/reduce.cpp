#include "kernels/core/reduce.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace dem {

void SegmentedTree::plan(const std::vector<std::pair<int, int>>& ranges) {
  segments_ = static_cast<int>(ranges.size());
  levels_.clear();
  slots_ = 0;
  // Each segment still being reduced: its items at this level, [begin, end) in the level's input.
  struct Open {
    int segment, begin, end;
  };
  std::vector<Open> open;
  for (int s = 0; s < segments_; ++s) {
    const auto& r = ranges[static_cast<std::size_t>(s)];
    if (r.second < r.first || r.first < 0)
      throw std::invalid_argument("SegmentedTree: segment " + std::to_string(s) + " has items [" +
                                  std::to_string(r.first) + ", " + std::to_string(r.second) + ")");
    open.push_back({s, r.first, r.second});
  }
  while (!open.empty()) {
    std::vector<ReduceBlock> list;
    std::vector<Open> next;
    int slot = 0;
    for (const Open& o : open) {
      const int n = o.end - o.begin;
      if (n <= kReduceBlock) {  // one block: the segment's root (no items: zeros)
        list.push_back({o.begin, o.end, -1 - o.segment});
        continue;
      }
      const int first = slot;
      for (int b = o.begin; b < o.end; b += kReduceBlock)
        list.push_back({b, std::min(o.end, b + kReduceBlock), slot++});
      next.push_back({o.segment, first, slot});
    }
    Level level;
    level.count = static_cast<int>(list.size());
    level.first_slot = slots_;
    level.blocks = ReduceBlockView(Kokkos::view_alloc(Kokkos::WithoutInitializing, "dem::reduce::blocks"), list.size());
    Kokkos::deep_copy(level.blocks,
                      Kokkos::View<const ReduceBlock*, HostSpace, Kokkos::MemoryUnmanaged>(list.data(), list.size()));
    levels_.push_back(level);
    slots_ += static_cast<std::size_t>(slot);
    open.swap(next);
  }
}

int exclusive_scan(const char* label, const IndexView& counts, const IndexView& offsets, int n) {
  int total = 0;
  Kokkos::parallel_scan(label, RangePolicy(0, n + 1),
      KOKKOS_LAMBDA(const int i, int& acc, const bool final) {
        const int c = i < n ? counts(i) : 0;
        if (final) offsets(i) = acc;
        acc += c;
      }, total);
  return total;
}

Kokkos::View<Real*, MemSpace> reduce_scratch(std::size_t count) {
  // Freed by Kokkos::finalize's hook: a View that outlives the backend would be freed after it.
  static Kokkos::View<Real*, MemSpace>* buffer = nullptr;
  if (buffer == nullptr) {
    buffer = new Kokkos::View<Real*, MemSpace>();
    Kokkos::push_finalize_hook([] {
      delete buffer;
      buffer = nullptr;
    });
  }
  if (buffer->extent(0) < count)
    *buffer = Kokkos::View<Real*, MemSpace>(Kokkos::view_alloc(Kokkos::WithoutInitializing, "dem::reduce::scratch"),
                                            2 * count);
  return *buffer;
}

Kokkos::View<Real*, MemSpace> reduce_root() {
  static Kokkos::View<Real*, MemSpace>* root = nullptr;
  if (root == nullptr) {
    root = new Kokkos::View<Real*, MemSpace>("dem::reduce::root", kMaxReduceValues);
    Kokkos::push_finalize_hook([] {
      delete root;
      root = nullptr;
    });
  }
  return *root;
}

void read_root(Real* out, int count) {
  Kokkos::deep_copy(Kokkos::View<Real*, HostSpace, Kokkos::MemoryUnmanaged>(out, count),
                    Kokkos::subview(reduce_root(), std::make_pair(0, count)));
}

}  // namespace dem
