#pragma once
/// Where a step's statistics wait on the device until the host reads them: a ring of rows, one per step, that the
/// step's reductions write their roots to (the leapfrog's sums and maxima, the membrane's, the fastest membrane
/// node, the largest overlaps). On a GPU, reading them at every step would hold the host at every step; the
/// Simulation reads them every few steps instead (SimParams::stats_every), and whenever a decision needs them
/// (host/engine/step_reads.cpp says how a rebuild is decided between reads with the same outcome).
#include "host/config/config.hpp"
#include "kernels/motion/integrate.hpp"
#include "kernels/motion/membrane.hpp"

namespace dem {

struct StepRows {
  /// Steps the ring holds: the most that SimParams::stats_every may ask for.
  static constexpr int kSlots = static_cast<int>(kMaxStatsEvery);
  /// A row's columns: the leapfrog's values (Leapfrog), the membrane's (membrane_integrate_to), the fastest
  /// membrane node (m/s), the periodic cell's stretch_speed (m/s), the speed of a wall a servo on the device steers (m/s).
  enum Column : int {
    kLeapfrog = 0,
    kMembrane = kLeapfrog + Leapfrog::kValues,
    kNodeSpeed = kMembrane + kMembraneValues,
    kCellSpeed = kNodeSpeed + 1,
    kWallSpeed = kCellSpeed + 1,
    kColumns = kWallSpeed + 1
  };
  /// The overlaps of a row: ball-ball and ball-wall.
  enum Overlap : int { kBalls = 0, kWalls = 1 };

  StepRowsView rows;
  OverlapRowsView overlaps;
  decltype(Kokkos::create_mirror_view(StepRowsView())) host_rows;
  decltype(Kokkos::create_mirror_view(OverlapRowsView())) host_overlaps;

  StepRows()
      : rows("dem::sim::step_rows", kSlots, kColumns),
        overlaps("dem::sim::overlap_rows", kSlots),
        host_rows(Kokkos::create_mirror_view(rows)),
        host_overlaps(Kokkos::create_mirror_view(overlaps)) {}

  static int slot(long step) { return static_cast<int>(step % kSlots); }
  /// Device address of step `step`'s first value in column `c` (through subviews: the host may not index device
  /// memory).
  Real* at(long step, Column c) const {
    return Kokkos::subview(rows, slot(step), std::make_pair(static_cast<int>(c), static_cast<int>(kColumns))).data();
  }
  OverlapResultView overlap(long step, Overlap o) const {
    return OverlapResultView(Kokkos::subview(overlaps, slot(step), static_cast<int>(o)).data());
  }
  /// The rows of steps [from, to) to the host (to - from <= kSlots): two copies, four where they wrap around.
  void read(long from, long to) const {
    const int a = slot(from), b = slot(to - 1) + 1;
    const auto part = [&](int lo, int hi) {
      const auto r = std::make_pair(lo, hi);
      Kokkos::deep_copy(Kokkos::subview(host_rows, r, Kokkos::ALL), Kokkos::subview(rows, r, Kokkos::ALL));
      Kokkos::deep_copy(Kokkos::subview(host_overlaps, r, Kokkos::ALL), Kokkos::subview(overlaps, r, Kokkos::ALL));
    };
    if (a < b) {
      part(a, b);
    } else {
      part(a, kSlots);
      part(0, b);
    }
  }
  const Real* host_row(long step) const { return &host_rows(slot(step), 0); }
  OverlapStat host_overlap(long step, Overlap o) const { return host_overlaps(slot(step), o); }
};

}  // namespace dem
