#include "kernels/motion/cell_servo.hpp"

namespace dem {

namespace {
/// Particle i's position, and its position at the last rebuild, stretched by `st`.
KOKKOS_INLINE_FUNCTION void stretch_particle(const Vec3View& x, const Vec3View& xr, int i, const CellStretch& st) {
  for (int d = 0; d < 3; ++d) {
    x(i, d) = st(d, x(i, d));
    xr(i, d) = st(d, xr(i, d));
  }
}
}  // namespace

void cell_servo_rates(const CellView& cell, const CellServoSpec& spec, const CellServoSumsView& sums,
                      bool fresh_stiffness, Real dt) {
  Kokkos::parallel_for("dem::cell_servo::rates", RangePolicy(0, 1), KOKKOS_LAMBDA(const int) {
    servo_cell(cell(), spec, sums.data(), fresh_stiffness, dt);
  });
}

void cell_servo_rates(const SpecimenParamsView& spec, const CellServoSlotView& slots, const CellServoSumRowsView& sums) {
  Kokkos::parallel_for("dem::cell_servo::batch_rates", RangePolicy(0, static_cast<int>(slots.extent(0))),
                       KOKKOS_LAMBDA(const int s) {
    CellServoSlot& slot = slots(s);
    if (!slot.on) return;
    const bool fresh = slot.calls++ % slot.spec.stiffness_every == 0;
    servo_cell(spec(s).dom, slot.spec, &sums(s, 0), fresh, spec(s).integ.dt);
  });
}

void stretch_cell(const Particles& p, const CellView& cell, Real dt, Real reach, Real* speed) {
  auto x = p.x, xr = p.x_ref;
  const int n = p.n;
  Kokkos::parallel_for("dem::cell_servo::stretch", RangePolicy(0, n > 0 ? n : 1), KOKKOS_LAMBDA(const int i) {
    // Every item reads the cell's lo and rates, which no item writes; the first alone moves its upper bounds,
    // which no item reads.
    const CellStretch st(cell(), dt);
    if (i < n) stretch_particle(x, xr, i, st);
    if (i == 0) {
      st.apply(cell());
      *speed = stretch_speed(cell(), reach);
    }
  });
}

void stretch_cells(const Particles& p, const SpecimenParamsView& spec, const Kokkos::View<const char*, MemSpace>& on,
                   const CellServoSlotView& slots, Real* speeds, int stride) {
  auto x = p.x, xr = p.x_ref;
  auto owner = p.specimen;
  Kokkos::parallel_for("dem::cell_servo::stretch_batch", RangePolicy(0, p.n), KOKKOS_LAMBDA(const int i) {
    const int s = owner(i);
    if (!on(s)) return;
    stretch_particle(x, xr, i, CellStretch(spec(s).dom, spec(s).integ.dt));
  });
  // The cells after their particles, in a launch of their own: no item writes a cell that another reads.
  Kokkos::parallel_for("dem::cell_servo::stretch_batch_cells", RangePolicy(0, static_cast<int>(spec.extent(0))),
                       KOKKOS_LAMBDA(const int s) {
    if (!on(s)) return;
    Domain& dom = spec(s).dom;
    CellStretch(dom, spec(s).integ.dt).apply(dom);
    if (slots(s).on) speeds[s * stride] = stretch_speed(dom, slots(s).reach);
  });
}

}  // namespace dem
