#pragma once
/// A Simulation's whole dynamic state as host vectors: what a checkpoint holds so that a resumed run goes on
/// bit for bit. The particles are kept in their current local order and both contact lists as they are
/// (history, flags, the extensions' slots), with the rebuild bookkeeping, so that the resumed run rebuilds its neighbour lists
/// at the same steps and gathers forces in the same order as the run it continues.
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "kernels/core/domain.hpp"
#include "kernels/motion/integrate.hpp"

namespace dem {

/// One contact list: keys, local indices and history. Vectors are interleaved (x0, y0, z0, x1, ...).
struct SavedContacts {
  std::vector<std::uint64_t> key;
  std::vector<int> i, j;
  std::vector<double> fs, mr;         ///< history: N, N m
  std::array<std::vector<double>, kHistorySlots> slot;  ///< the extensions' history (HistorySlot)
  std::vector<std::uint8_t> flags;
  std::vector<double> fc, mt, fn;     ///< the last step's forces (N, N m, N): what wall forces and records read
};

struct SimState {
  long step = 0;
  double time = 0, dt = 0;            ///< s
  Domain domain;
  // Particles, local order; x, v, w, f, m, x_ref interleaved.
  std::vector<double> x, v, w, f, m, x_ref, radius, mass, inertia;
  std::vector<std::uint32_t> gid;
  std::vector<int> specimen, material;
  SavedContacts balls, walls;
  std::vector<double> wall_point, wall_velocity;  ///< analytic walls, interleaved (m, m/s)
  std::vector<double> node_x, node_v;             ///< facet mesh nodes, interleaved (m, m/s)
  double cell_pressure = 0;                       ///< Pa
  double wall_disp = 0;                           ///< boundary travel since the last rebuild (m)
  StepStats stats;                                ///< of the last step (the next rebuild reads max_disp2)
  bool fresh = true;                              ///< no neighbour list yet
};

/// Checks a state read from a file before anything uses it: counts agree, every index is inside what it
/// indexes (gids a permutation of 0 .. n-1, materials below `materials`, contact keys sorted and naming existing
/// particles and wall objects, walls then facets, with i and j those of their key) and every value is finite
/// (radius, mass and inertia positive). Throws std::runtime_error naming the array, the row and the allowed range.
void check_state(const SimState& s, std::size_t walls, std::size_t facets, int materials);

}  // namespace dem
