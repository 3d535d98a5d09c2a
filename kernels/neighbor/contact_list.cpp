#include "kernels/neighbor/contact_list.hpp"

#include <Kokkos_Sort.hpp>

#include "kernels/core/buffers.hpp"

namespace dem {

ContactList::ContactList(int count)
    : key("dem::contacts::key", count), i("dem::contacts::i", count), j("dem::contacts::j", count),
      fs("dem::contacts::fs", count), mr("dem::contacts::mr", count), flags("dem::contacts::flags", count),
      fc("dem::contacts::fc", count), mo("dem::contacts::mo", count), mt("dem::contacts::mt", count), fn("dem::contacts::fn", count), n(count) {
  for (int s = 0; s < kHistorySlots; ++s) slot[s] = ScalarView(std::string("dem::contacts::") + kHistorySlotNames[s], count);
}

namespace {

/// The bins of bin_sort_keys: nbins uniform in the dense number of the keys from first to last.
struct DenseKeyBins {
  std::uint64_t span = 1, first = 0;
  double scale = 0;  ///< bins per unit of the dense number
  int nbins = 1;

  KOKKOS_INLINE_FUNCTION std::uint64_t dense(std::uint64_t k) const { return key_hi(k) * span + key_lo(k); }
  KOKKOS_INLINE_FUNCTION int bin(std::uint64_t k) const {
    const int b = static_cast<int>(static_cast<double>(dense(k) - first) * scale);
    return b < nbins - 1 ? b : nbins - 1;
  }
};

/// The bins for n keys (n / 2 + 1 of them, a few keys each), or nbins 0 where all keys are one.
DenseKeyBins bins_of(const PairKeyView& keys, int n) {
  Kokkos::MinMaxScalar<std::uint64_t> range;
  Kokkos::parallel_reduce("dem::contacts::key_range", RangePolicy(0, n),
      KOKKOS_LAMBDA(const int i, Kokkos::MinMaxScalar<std::uint64_t>& acc) {
        acc.min_val = keys(i) < acc.min_val ? keys(i) : acc.min_val;
        acc.max_val = keys(i) > acc.max_val ? keys(i) : acc.max_val;
      }, Kokkos::MinMax<std::uint64_t>(range));
  std::uint32_t lo_max = 0;
  Kokkos::parallel_reduce("dem::contacts::key_lo_max", RangePolicy(0, n),
      KOKKOS_LAMBDA(const int i, std::uint32_t& acc) { acc = key_lo(keys(i)) > acc ? key_lo(keys(i)) : acc; },
      Kokkos::Max<std::uint32_t>(lo_max));
  DenseKeyBins op;
  if (range.min_val == range.max_val) {
    op.nbins = 0;
    return op;
  }
  op.span = std::uint64_t(lo_max) + 1;
  op.first = op.dense(range.min_val);
  op.nbins = n / 2 + 1;
  op.scale = static_cast<double>(op.nbins - 1) / static_cast<double>(op.dense(range.max_val) - op.first);
  return op;
}

}  // namespace

void bin_sort_keys(const PairKeyView& keys, KeySortBuffers& kept) {
  const int n = static_cast<int>(keys.extent(0));
  if (n < 2) return;
  const DenseKeyBins op = bins_of(keys, n);
  const int nb = op.nbins;
  if (nb == 0) return;
  const IndexView count = room(kept.count, nb, "dem::contacts::sort_count");
  const IndexView fill = room(kept.fill, nb, "dem::contacts::sort_fill");
  const IndexView offset = room(kept.offset, nb, "dem::contacts::sort_offset");
  const PairKeyView sorted = room(kept.sorted, n, "dem::contacts::sort_keys");
  Kokkos::parallel_for("dem::contacts::sort_zero", RangePolicy(0, nb), KOKKOS_LAMBDA(const int b) {
    count(b) = 0;
    fill(b) = 0;
  });
  Kokkos::parallel_for("dem::contacts::sort_count", RangePolicy(0, n),
      KOKKOS_LAMBDA(const int i) { Kokkos::atomic_increment(&count(op.bin(keys(i)))); });
  // No total read back (the keys' count is known).
  Kokkos::parallel_scan("dem::contacts::sort_offset", RangePolicy(0, nb),
      KOKKOS_LAMBDA(const int b, int& acc, const bool final) {
        if (final) offset(b) = acc;
        acc += count(b);
      });
  // Each key to its bin's range, in an order the atomics decide; the bin's own sort below makes it the keys' order.
  Kokkos::parallel_for("dem::contacts::sort_place", RangePolicy(0, n), KOKKOS_LAMBDA(const int i) {
    const int b = op.bin(keys(i));
    sorted(offset(b) + Kokkos::atomic_fetch_add(&fill(b), 1)) = keys(i);
  });
  Kokkos::parallel_for("dem::contacts::sort_bins", RangePolicy(0, nb), KOKKOS_LAMBDA(const int b) {
    const int lo = offset(b), hi = lo + count(b);
    for (int k = lo + 1; k < hi; ++k) {
      const std::uint64_t v = sorted(k);
      int m = k;
      for (; m > lo && sorted(m - 1) > v; --m) sorted(m) = sorted(m - 1);
      sorted(m) = v;
    }
  });
  // A copy in a kernel: a deep_copy waits for the device.
  Kokkos::parallel_for("dem::contacts::sort_back", RangePolicy(0, n),
      KOKKOS_LAMBDA(const int i) { keys(i) = sorted(i); });
}

void sort_keys(const PairKeyView& keys, KeySortBuffers& kept) {
  if (Kokkos::SpaceAccessibility<HostSpace, MemSpace>::accessible)
    Kokkos::sort(keys);  // std::sort
  else
    bin_sort_keys(keys, kept);
}

}  // namespace dem
