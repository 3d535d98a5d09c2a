#include "host/util/sync_counts.hpp"

#include <cstdint>
#include <cstring>

#include "kernels/core/types.hpp"

namespace dem {

namespace {

// The callbacks are plain functions: one tally per process, kept by the one host thread that launches kernels.
SyncTally tally;
SyncPart current = SyncPart::kOther;
bool counting = false;

SyncCounts& now() { return tally[static_cast<int>(current)]; }

void on_for(const char*, std::uint32_t, std::uint64_t*) { ++now().launches; }
void on_reduce(const char* name, std::uint32_t, std::uint64_t*) {
  ++now().launches;
  const std::size_t n = std::strlen(name), tag = std::strlen(TRIAXDEM_DEVICE_RESULT);
  const bool on_device = n >= tag && std::strcmp(name + n - tag, TRIAXDEM_DEVICE_RESULT) == 0;
  if (!on_device) ++now().host_results;
}
void on_scan(const char*, std::uint32_t, std::uint64_t*) {
  ++now().launches;
  ++now().host_results;
}
void on_allocate(Kokkos_Profiling_SpaceHandle, const char*, const void*, std::uint64_t) { ++now().allocations; }
void on_copy(Kokkos_Profiling_SpaceHandle, const char*, const void*, Kokkos_Profiling_SpaceHandle, const char*,
             const void*, std::uint64_t) {
  ++now().copies;
}

}  // namespace

bool count_syncs() {
  if (counting) return true;
  if (Kokkos::Tools::profileLibraryLoaded()) return false;
  namespace T = Kokkos::Tools::Experimental;
  T::set_begin_parallel_for_callback(on_for);
  T::set_begin_parallel_reduce_callback(on_reduce);
  T::set_begin_parallel_scan_callback(on_scan);
  T::set_allocate_data_callback(on_allocate);
  T::set_begin_deep_copy_callback(on_copy);
  counting = true;
  return true;
}

SyncTally sync_tally() { return tally; }

void count_fence() { ++now().fences; }

SyncScope::SyncScope(SyncPart part) : before_(current) { current = part; }

SyncScope::~SyncScope() { current = before_; }

}  // namespace dem
