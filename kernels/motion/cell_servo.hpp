#pragma once
/// The periodic cell steered on the device: the strain-rate servo of the cell test's stages
/// (host/triax/periodic_stages.hpp) and the cell's affine step. A Simulation whose cell the servo steers keeps the
/// cell in device memory (CellView), where these kernels change it and the force and integration kernels read it, so
/// that a step waits for nothing on the host (host/engine/simulation.hpp: set_cell_servo). The servo's arithmetic is
/// here once: the host's servo (a walled cell, a batch) calls the same functions.
#include "kernels/core/particles.hpp"
#include "kernels/core/specimen.hpp"

namespace dem {

/// What the servo does with each axis of the cell before a step.
struct CellServoSpec {
  bool servo[3] = {false, false, false};  ///< axis d servoed to its target stress; else its rate is fixed[d]
  Real fixed[3] = {0, 0, 0};              ///< 1/s, extension positive
  Real sigma3 = 0;                        ///< Pa, the target's confining part (compression positive)
  Real membrane_stiffness = 0;            ///< Pa, the target's membrane part (membrane_confinement); 0: none
  Real L0[3] = {1, 1, 1};                 ///< m, the lengths the membrane's strain counts from
  Real alpha = 0;                         ///< the servo's gain as a fraction of the stiffness (0, 1]
  Real max_rate = 0;                      ///< 1/s, the servoed rates' clamp
  /// 1/s, the clamp instead while the cell's volume is above gas_volume (m^3): a cell that holds a gas, far from
  /// jamming, may close faster than a packing may form; 0 (or below max_rate): max_rate throughout.
  Real gas_rate = 0;
  Real gas_volume = 0;
  int stiffness_every = 1;                ///< the stiffness is summed on one call in this many, from the first
};

/// Membrane extension: the extra lateral confinement (Pa) of a membrane of stiffness E_m t / R0 (Pa, its modulus times
/// thickness over the specimen's radius) at lateral strain eps (extension positive): the hoop tension E_m t eps of a
/// thin cylinder acting on the radius R0. None in contraction: latex buckles rather than push. In the periodic cell
/// each lateral axis is servoed to sigma3 plus this, and q is reported against sigma3, the cell pressure, as a lab
/// does.
KOKKOS_INLINE_FUNCTION Real membrane_confinement(Real stiffness, Real eps) { return stiffness * (eps < 0 ? Real(0) : eps); }

/// The target stress (Pa) of axis d at length L (m): sigma3 plus the membrane's.
KOKKOS_INLINE_FUNCTION Real servo_target(const CellServoSpec& s, int d, Real L) {
  return s.sigma3 + membrane_confinement(s.membrane_stiffness, L / s.L0[d] - 1);
}

/// The servoed rates' clamp (1/s) of a cell of volume V (m^3): the gas phase's above gas_volume, else max_rate.
KOKKOS_INLINE_FUNCTION Real servo_clamp(const CellServoSpec& s, Real V) {
  return s.gas_rate > s.max_rate && V > s.gas_volume ? s.gas_rate : s.max_rate;
}

/// The servoed rate (1/s) for stress error err = sigma - target (Pa) at stiffness k (Pa) over a step of dt (s) in a
/// cell of volume V (m^3): alpha err / (k dt), so that the step corrects the fraction alpha of the error, clamped to
/// +-servo_clamp; with no contacts (k = 0) the clamp decides.
KOKKOS_INLINE_FUNCTION Real servo_rate(const CellServoSpec& s, Real err, Real k, Real dt, Real V) {
  const Real clamp = servo_clamp(s, V);
  const Real r = k > 0 ? s.alpha * err / (k * dt) : (err > 0 ? clamp : (err < 0 ? -clamp : Real(0)));
  return r < -clamp ? -clamp : (clamp < r ? clamp : r);
}

/// The fastest the servo can move two balls within `reach` (m) of each other apart or together (m/s): the host's bound
/// on the cell's share of the neighbour lists' travel over the steps it has not read (stretch_speed's, at the clamp).
inline Real servo_speed_bound(const CellServoSpec& s, Real reach) {
  Real rate = 0;
  for (int d = 0; d < 3; ++d) {
    const Real r = s.servo[d] ? (s.gas_rate > s.max_rate ? s.gas_rate : s.max_rate) : kc::fabs(s.fixed[d]);
    rate = r > rate ? r : rate;
  }
  return rate * reach;
}

/// The host's copy of a cell the servo steers: it takes the rates the kernel gives the fixed axes.
inline void take_fixed_rates(Domain& dom, const CellServoSpec& s) {
  for (int d = 0; d < 3; ++d)
    if (!s.servo[d]) dom.strain_rate[d] = s.fixed[d];
}

/// The host's copy of a cell over a step of dt: stretched along the axes whose rate the host knows, every axis
/// where no servo steers it (`servo` null), else the axes it does not servo; the device stretches its own alike.
inline void stretch_known_axes(Domain& dom, const CellServoSpec* servo, Real dt) {
  const CellStretch st(dom, dt);
  for (int d = 0; d < 3; ++d)
    if (!servo || !servo->servo[d]) dom.hi[d] = st(d, dom.hi[d]);
}

/// Where the servo keeps its sums between kernels, in device memory: the stiffness's sums (K_dd V) and the contact
/// stress's (sigma_dd V) of this call, the stiffness of the call that last summed it (Pa).
struct CellServoSums {
  enum : int { kStiffnessSums = 0, kStressSums = 3, kStiffness = 6, kCount = 9 };
};
using CellServoSumsView = Kokkos::View<Real[CellServoSums::kCount], MemSpace>;
/// A batch's: a row per specimen.
using CellServoSumRowsView = Kokkos::View<Real* [CellServoSums::kCount], Kokkos::LayoutRight, MemSpace>;

/// One cell's servo: the rates of `dom` for the next step from its sums (CellServoSums; the stiffness's where
/// `fresh_stiffness`), as the host's CellServo sets them.
KOKKOS_INLINE_FUNCTION void servo_cell(Domain& dom, const CellServoSpec& spec, Real* sums, bool fresh_stiffness,
                                       Real dt) {
  // The same divisions as the host's cell_stiffness and contact_stress_diagonal: the same bits.
  const Real V = dom.volume();
  for (int d = 0; d < 3; ++d) {
    if (fresh_stiffness) sums[CellServoSums::kStiffness + d] = sums[CellServoSums::kStiffnessSums + d] / V;
    if (!spec.servo[d]) {
      dom.strain_rate[d] = spec.fixed[d];
      continue;
    }
    const Real err = sums[CellServoSums::kStressSums + d] / V - servo_target(spec, d, dom.length(d));
    dom.strain_rate[d] = servo_rate(spec, err, sums[CellServoSums::kStiffness + d], dt, V);
  }
}

/// Sets the cell's rates for the next step from the sums in `sums`: one work item.
void cell_servo_rates(const CellView& cell, const CellServoSpec& spec, const CellServoSumsView& sums,
                      bool fresh_stiffness, Real dt);

/// A batch specimen's servo on the device: its spec, while `on`; the calls it has had (the stiffness is summed on the
/// first and one in spec.stiffness_every after); the reach of its neighbour lists (m: stretch_speed's).
struct CellServoSlot {
  CellServoSpec spec;
  Real reach = 0;
  long calls = 0;
  int on = 0;
};
using CellServoSlotView = Kokkos::View<CellServoSlot*, MemSpace>;

/// The batch's servos: the rates of each specimen whose slot is on, from its row of `sums`, one work item each.
void cell_servo_rates(const SpecimenParamsView& spec, const CellServoSlotView& slots, const CellServoSumRowsView& sums);

/// The periodic cell's affine step over dt at the rates the cell holds: positions and the positions of the last
/// rebuild stretched about lo (CellStretch), the cell's upper bounds likewise, and stretch_speed(reach) of the step
/// to `speed`, in device memory.
void stretch_cell(const Particles& p, const CellView& cell, Real dt, Real reach, Real* speed);

/// The same for each specimen s of a batch marked in `on`, at its cell's rates and time step; where its servo's slot
/// is on, its stretch_speed goes to speeds[s * stride].
void stretch_cells(const Particles& p, const SpecimenParamsView& spec, const Kokkos::View<const char*, MemSpace>& on,
                   const CellServoSlotView& slots, Real* speeds, int stride);

}  // namespace dem
