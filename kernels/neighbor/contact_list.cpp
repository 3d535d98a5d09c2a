#include "kernels/neighbor/contact_list.hpp"

#include <Kokkos_Sort.hpp>

namespace dem {

ContactList::ContactList(int count)
    : key("dem::contacts::key", count), i("dem::contacts::i", count), j("dem::contacts::j", count),
      fs("dem::contacts::fs", count), mr("dem::contacts::mr", count), flags("dem::contacts::flags", count),
      fc("dem::contacts::fc", count), mo("dem::contacts::mo", count), mt("dem::contacts::mt", count), fn("dem::contacts::fn", count), n(count) {
  for (int s = 0; s < kHistorySlots; ++s) slot[s] = ScalarView(std::string("dem::contacts::") + kHistorySlotNames[s], count);
}

namespace {

/// The bins of bin_sort_keys (a Kokkos::BinSort bin operator).
struct DenseKeyBins {
  std::uint64_t span = 1, first = 0;
  double scale = 0;  ///< bins per unit of the dense number
  int nbins = 1;

  KOKKOS_INLINE_FUNCTION std::uint64_t dense(std::uint64_t k) const { return key_hi(k) * span + key_lo(k); }
  template <class Keys>
  KOKKOS_INLINE_FUNCTION int bin(Keys& keys, const int& i) const {
    const int b = static_cast<int>(static_cast<double>(dense(keys(i)) - first) * scale);
    return b < nbins - 1 ? b : nbins - 1;
  }
  KOKKOS_INLINE_FUNCTION int max_bins() const { return nbins; }
  template <class Keys, class I1, class I2>
  KOKKOS_INLINE_FUNCTION bool operator()(Keys& keys, I1& a, I2& b) const {
    return keys(a) < keys(b);
  }
};

}  // namespace

void bin_sort_keys(const PairKeyView& keys) {
  const int n = static_cast<int>(keys.extent(0));
  if (n < 2) return;
  Kokkos::MinMaxScalar<std::uint64_t> range;
  Kokkos::parallel_reduce("dem::contacts::key_range", RangePolicy(0, n),
      KOKKOS_LAMBDA(const int i, Kokkos::MinMaxScalar<std::uint64_t>& acc) {
        acc.min_val = keys(i) < acc.min_val ? keys(i) : acc.min_val;
        acc.max_val = keys(i) > acc.max_val ? keys(i) : acc.max_val;
      }, Kokkos::MinMax<std::uint64_t>(range));
  const std::uint64_t first = range.min_val, last = range.max_val;
  std::uint32_t lo_max = 0;
  Kokkos::parallel_reduce("dem::contacts::key_lo_max", RangePolicy(0, n),
      KOKKOS_LAMBDA(const int i, std::uint32_t& acc) { acc = key_lo(keys(i)) > acc ? key_lo(keys(i)) : acc; },
      Kokkos::Max<std::uint32_t>(lo_max));
  if (first == last) return;
  DenseKeyBins op;
  op.span = std::uint64_t(lo_max) + 1;
  op.first = op.dense(first);
  op.nbins = n / 2 + 1;
  op.scale = static_cast<double>(op.nbins - 1) / static_cast<double>(op.dense(last) - op.first);
  Kokkos::BinSort<PairKeyView, DenseKeyBins> sorter(keys, op, true);
  sorter.create_permute_vector();
  sorter.sort(keys);
}

void sort_keys(const PairKeyView& keys) {
  if (Kokkos::SpaceAccessibility<HostSpace, MemSpace>::accessible)
    Kokkos::sort(keys);  // std::sort
  else
    bin_sort_keys(keys);
}

}  // namespace dem
