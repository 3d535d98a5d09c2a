#pragma once
/// All device-side types of triaxdem, in one place. No other file spells out Kokkos::View template
/// arguments: a change of layout or precision happens here and is measured in perf/.
#include <Kokkos_Core.hpp>
#include <cstdint>
#include <type_traits>

#include "kernels/core/contact_params.hpp"

namespace dem {

using ExecSpace = Kokkos::DefaultExecutionSpace;
using MemSpace = ExecSpace::memory_space;
using HostSpace = Kokkos::HostSpace;
/// The execution space's natural layout: LayoutRight on CPUs (a 3-vector is one cache line for
/// gathers through neighbour indices), LayoutLeft on GPUs (coalesced components). perf/ measures both.
using Layout = ExecSpace::array_layout;
/// Whether the kernels run on an accelerator. Processes that share one time-slice it: on an H100, 4 calibration
/// cells as 4 processes ran 4.7 times slower together than one alone (docs/performance.md), so a device build runs
/// one simulation at a time.
constexpr bool kOnDevice = !std::is_same<MemSpace, HostSpace>::value;

using Vec3View = Kokkos::View<Real* [3], Layout, MemSpace>;          ///< per-item 3-vector (m, m/s, N, ...)
using ConstVec3View = Kokkos::View<const Real* [3], Layout, MemSpace>;
using ScalarView = Kokkos::View<Real*, MemSpace>;                    ///< per-item scalar (m, kg, kg m^2, ...)
using ConstScalarView = Kokkos::View<const Real*, MemSpace>;
using IndexView = Kokkos::View<int*, MemSpace>;                      ///< local indices, counts, offsets
using ConstIndexView = Kokkos::View<const int*, MemSpace>;
using GidView = Kokkos::View<std::uint32_t*, MemSpace>;             ///< global particle id (stable across sorts)
using PairKeyView = Kokkos::View<std::uint64_t*, MemSpace>;         ///< sorted contact key (see contact_list.hpp)
using FlagView = Kokkos::View<std::uint8_t*, MemSpace>;             ///< per-contact state bits
using Index2View = Kokkos::View<int* [2], Layout, MemSpace>;         ///< pair of local indices
using Real2View = Kokkos::View<Real* [2], Kokkos::LayoutRight, MemSpace>;  ///< two values per item
using Index3View = Kokkos::View<int* [3], Layout, MemSpace>;         ///< facet vertex indices

/// Host memory for the copies a record takes of the device's state (host/engine/state_copy.hpp): pinned where a
/// device steps, so that a copy runs at the link's speed with no staging buffer of the driver's in between.
#ifdef KOKKOS_ENABLE_CUDA
using CopySpace = Kokkos::CudaHostPinnedSpace;
#else
using CopySpace = HostSpace;
#endif
/// A kept host copy of a device View V: its type and layout, in CopySpace.
template <class V>
using HostCopyView = Kokkos::View<typename V::non_const_data_type, typename V::array_layout, CopySpace>;

/// Largest overlap / radius of a step's contacts and where it happened (for blow-up detection).
struct OverlapStat {
  Real ratio = 0;
  int contact = -1;
};

/// What the balls load a wall object with: the force (N) and the touching contacts, side by side so that a servo
/// reads both in one copy.
struct WallLoad {
  Real force[3] = {0, 0, 0};
  int touching = 0;
};
using WallLoadView = Kokkos::View<WallLoad*, MemSpace>;

/// A step's statistics, kept on the device, a row per step of a ring of steps (host/engine/step_rows.hpp): the
/// reductions' roots as Reals, and the largest overlaps of the ball-ball and ball-wall contacts.
using StepRowsView = Kokkos::View<Real**, Kokkos::LayoutRight, MemSpace>;
using OverlapRowsView = Kokkos::View<OverlapStat* [2], Kokkos::LayoutRight, MemSpace>;
/// One overlap of such a row, where a reduction leaves its result without the host waiting for it.
using OverlapResultView = Kokkos::View<OverlapStat, MemSpace, Kokkos::MemoryUnmanaged>;
/// Ends the label of a parallel_reduce whose result stays in device memory, so that the sync counter
/// (host/util/sync_counts.hpp) tells it from one whose value the host waits for.
#define TRIAXDEM_DEVICE_RESULT "@device"

/// Contact parameters per pair of material indices (contact_law.hpp).
using ParamTableView = Kokkos::View<ContactParams**, MemSpace>;

using RangePolicy = Kokkos::RangePolicy<ExecSpace>;

/// Contact flags (bits of FlagView).
enum ContactFlag : std::uint8_t {
  kTouching = 1u << 0,  ///< overlapping this step
  kSliding = 1u << 1,   ///< shear force at the Coulomb cap
  kRolling = 1u << 2,   ///< rolling moment at its cap
};

}  // namespace dem
