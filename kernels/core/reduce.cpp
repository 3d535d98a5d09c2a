#include "kernels/core/reduce.hpp"

namespace dem {

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

}  // namespace dem
