#pragma once
/// What the host makes the device wait for, counted through Kokkos' tool callbacks, by the part of the time loop it
/// happens in. On a GPU an allocation, a deep copy and a reduction whose value the host reads on return each hold
/// the host until the device is done; on a CPU they cost next to nothing, but they are the same calls, so a count
/// taken on the CPU build is the GPU's. Kokkos 3.4 reports no global fence to the tools: the time loop's own fences
/// (its part timers) are counted by hand (count_fence).
#include <array>
#include <string>

namespace dem {

struct SyncCounts {
  long launches = 0;      ///< parallel_for, parallel_reduce and parallel_scan
  long host_results = 0;  ///< parallel_reduce and parallel_scan whose value the host reads on return (a reduction
                          ///< into device memory is labelled with TRIAXDEM_DEVICE_RESULT, kernels/core/types.hpp)
  long copies = 0;        ///< deep copies
  long allocations = 0;   ///< View allocations
  long fences = 0;        ///< the part timers' fences
  /// Waits of the host for the device: results read on return, copies and fences (an allocation waits on a
  /// GPU only when it frees what it replaces, so it is counted apart).
  long syncs() const { return host_results + copies + fences; }
  SyncCounts operator-(const SyncCounts& o) const {
    return {launches - o.launches, host_results - o.host_results, copies - o.copies, allocations - o.allocations,
            fences - o.fences};
  }
  SyncCounts operator+(const SyncCounts& o) const {
    return {launches + o.launches, host_results + o.host_results, copies + o.copies, allocations + o.allocations,
            fences + o.fences};
  }
};

/// Where in the time loop: the stage's control before a step (servo), the step less its rebuilds, a rebuild of the
/// neighbour lists, the stage's records and checkpoints after a step, and everything else (set-up, output).
enum class SyncPart { kOther, kControl, kStep, kRebuild, kRecord };
constexpr int kSyncParts = 5;
using SyncTally = std::array<SyncCounts, kSyncParts>;

/// Starts counting, once per process. Returns false, and counts nothing, where a profiling tool of the user's
/// (KOKKOS_TOOLS_LIBS) holds the callbacks: its own report then says more. Call after Kokkos is initialised.
bool count_syncs();
/// Every part's counts since count_syncs.
SyncTally sync_tally();
/// One fence of the time loop's timers.
void count_fence();

/// While it lives, what happens counts to `part`; the part before it counts again after.
class SyncScope {
 public:
  explicit SyncScope(SyncPart part);
  ~SyncScope();
  SyncScope(const SyncScope&) = delete;
  SyncScope& operator=(const SyncScope&) = delete;

 private:
  SyncPart before_;
};

}  // namespace dem
