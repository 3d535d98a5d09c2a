#pragma once
/// A specimen of a batch as the kernels see it: its cell, its time integration, its particles and its row of the
/// material-pair table. A simulation of one specimen gives its kernels the one by value; a batch of several, a
/// View of them, looked up by the specimen of a work item (Particles::specimen).
#include "kernels/core/domain.hpp"
#include "kernels/core/types.hpp"

namespace dem {

struct IntegrateParams {
  Vec3 gravity;           ///< m/s^2
  Real alpha = 0.7;       ///< local damping coefficient
  Real mass_scale = 1.0;  ///< density scaling factor for quasi-static runs (1 = physical)
  Real dt = 0;            ///< s
  bool measure = true;    ///< fill StepStats::unbalanced and ::kinetic (skipped on unmeasured steps)
  /// With about_flow, local damping acts on v - flow_rate (x - flow_origin), component by component: the
  /// velocity about the test's imposed mean flow. On the absolute velocity (PFC, the default) a steady flow
  /// turns the damping of the balls' fluctuating forces into a net drag against it (docs/performance.md: The
  /// triaxial test).
  bool about_flow = false;
  Vec3 flow_rate;         ///< 1/s, diagonal of the mean flow's velocity gradient
  Vec3 flow_origin;       ///< m, where the mean flow is at rest
};

struct SpecimenParams {
  Domain dom;
  IntegrateParams integ;
  int first = 0, count = 0;  ///< its particles [first, first + count)
  int material_row = 0;      ///< its materials' first row of the material-pair table
  Real overlap_limit = 0;    ///< overlap / radius past which a contact is a blow-up (listed by a batch's force kernel)
};
using SpecimenParamsView = Kokkos::View<SpecimenParams*, MemSpace>;
/// A Simulation's cell in device memory, where the kernels of a cell steered on the device change it
/// (kernels/motion/cell_servo.hpp).
using CellView = Kokkos::View<Domain, MemSpace>;
using ConstCellView = Kokkos::View<const Domain, MemSpace>;

/// The specimens of a kernel: `one` where `many` is empty (a simulation of one specimen), else many(s). One
/// specimen's cell is `cell`, in device memory, where it is set, else one.dom: kernels take a cell by dom(s).
struct SpecimenTable {
  SpecimenParams one;
  Kokkos::View<const SpecimenParams*, MemSpace> many;
  ConstCellView cell;
  KOKKOS_INLINE_FUNCTION bool batched() const { return many.extent(0) > 0; }
  KOKKOS_INLINE_FUNCTION const SpecimenParams& operator()(const int s) const { return batched() ? many(s) : one; }
  KOKKOS_INLINE_FUNCTION const Domain& dom(const int s) const {
    return batched() ? many(s).dom : (cell.data() != nullptr ? cell() : one.dom);
  }
};

}  // namespace dem
