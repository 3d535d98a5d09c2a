#include "kernels/core/reduce.hpp"

namespace dem {

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
