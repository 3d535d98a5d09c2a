/// What a time step costs besides its arithmetic: kernel launches, allocations and copies
/// between memory spaces, counted through Kokkos' tool callbacks on steps that neither rebuild the neighbour list
/// nor record. A GPU pays for an allocation or a copy to the host with a wait; the goal is none on such a step.
/// (Kokkos 3.4 reports no global fence to the tools, so fences are not counted here.)
#include <gtest/gtest.h>

#include <string>

#include "host/config/config.hpp"
#include "host/cli/job.hpp"
#include "host/engine/setup.hpp"
#include "host/engine/simulation.hpp"

using namespace dem;

namespace {

struct Counts {
  long launches = 0, allocations = 0, copies = 0;
};
Counts counted;

void on_launch(const char*, std::uint32_t, std::uint64_t*) { ++counted.launches; }
void on_allocate(Kokkos_Profiling_SpaceHandle, const char*, const void*, std::uint64_t) { ++counted.allocations; }
void on_copy(Kokkos_Profiling_SpaceHandle, const char*, const void*, Kokkos_Profiling_SpaceHandle, const char*,
             const void*, std::uint64_t) {
  ++counted.copies;
}

/// Counts what f does, with the callbacks set only meanwhile.
template <class F>
Counts count_during(F&& f) {
  namespace T = Kokkos::Tools::Experimental;
  counted = Counts{};
  T::set_begin_parallel_for_callback(on_launch);
  T::set_begin_parallel_reduce_callback(on_launch);
  T::set_begin_parallel_scan_callback(on_launch);
  T::set_allocate_data_callback(on_allocate);
  T::set_begin_deep_copy_callback(on_copy);
  f();
  T::set_begin_parallel_for_callback(nullptr);
  T::set_begin_parallel_reduce_callback(nullptr);
  T::set_begin_parallel_scan_callback(nullptr);
  T::set_allocate_data_callback(nullptr);
  T::set_begin_deep_copy_callback(nullptr);
  return counted;
}

}  // namespace

// The run job's step (walls, 2,000 balls): forces, then the leapfrog with its tree reduction. Today the root of the
// reduction (unbalanced force, kinetic energy, the blow-up flag and the largest moves) comes back every step: one
// copy, which item 2 removes by keeping the statistics on the device and reading them every k steps.
TEST(HotPath, AStepAllocatesNothingAndReadsBackOneReductionsRoot) {
  Config cfg = load_config(std::string(TRIAXDEM_SOURCE_DIR) + "/configs/default.toml");
  auto sim = build_simulation(cfg, false);
  for (int k = 0; k < 50; ++k) sim->step(false);
  const long rebuilds = sim->times().rebuilds;
  const int steps = 20;
  const Counts c = count_during([&] {
    for (int k = 0; k < steps; ++k) sim->step(false);
  });
  ASSERT_EQ(sim->times().rebuilds, rebuilds) << "a rebuild in the counted steps";
  std::printf("per step: %.1f launches, %.1f allocations, %.1f copies\n", double(c.launches) / steps,
              double(c.allocations) / steps, double(c.copies) / steps);
  ASSERT_GT(c.launches, 0) << "the callbacks never fired: Kokkos built without its tools interface";
  EXPECT_EQ(c.allocations, 0);
  EXPECT_LE(c.copies, steps);
}
