#pragma once
/// Centred-difference (leapfrog) integration as in PFC, with gravity and local (Cundall) damping:
///   F_d = -alpha |F| sign(v), component-wise on forces and on moments (PFC manual; sign(0) = 0; v may be
///   taken about a mean flow, IntegrateParams::about_flow),
///   v(t + dt/2) = v(t - dt/2) + (F + F_d) / m dt,   x(t + dt) = x(t) + v(t + dt/2) dt.
/// Density scaling multiplies inertial mass and moment of inertia (not weight) by `mass_scale`.
#include "accumulate.hpp"
#include "particles.hpp"
#include "vec3.hpp"

namespace dem {

struct IntegrateParams {
  Vec3 gravity;           ///< m/s^2
  Real alpha = 0.7;       ///< local damping coefficient
  Real mass_scale = 1.0;  ///< density scaling factor for quasi-static runs (1 = physical)
  Real dt = 0;            ///< s
  bool measure = true;    ///< fill StepStats::unbalanced and ::kinetic (skipped on unmeasured steps)
  /// With about_flow, local damping acts on v - flow_rate (x - flow_origin), component by component: the
  /// velocity about the test's imposed mean flow. On the absolute velocity (PFC, the default) a steady flow
  /// turns the damping of the balls' fluctuating forces into a net drag against it (README: The triaxial test).
  bool about_flow = false;
  Vec3 flow_rate;         ///< 1/s, diagonal of the mean flow's velocity gradient
  Vec3 flow_origin;       ///< m, where the mean flow is at rest
};

/// Per-step sums over particles, for the unbalanced-force ratio and energy.
struct StepStats {
  Real unbalanced = 0;    ///< sum |F + m g| before damping (N), on measured steps
  Real kinetic = 0;       ///< translational + rotational kinetic energy (J), at t + dt/2, on measured steps
  Real max_disp2 = 0;     ///< largest squared displacement since the last rebuild (m^2)
  Real max_move2 = 0;     ///< largest (distance moved this step / radius)^2
  int bad = -1;           ///< a particle with a non-finite position, or -1
};

/// Completes each particle's force and moment (gather), stores them in p.f, p.m, and advances all
/// particles one step. Returns the step's sums (deterministic: fixed-order reduction).
StepStats integrate(Particles& p, const IntegrateParams& prm, const Gather& gather);

/// Local damping of one component: -alpha |F| sign(v).
KOKKOS_INLINE_FUNCTION Real local_damping(Real f, Real v, Real alpha) {
  const Real s = v > 0 ? Real(1) : (v < 0 ? Real(-1) : Real(0));
  return -alpha * kc::fabs(f) * s;
}

/// The velocity local damping is measured against (IntegrateParams::about_flow): v, or v less the mean flow at x.
KOKKOS_INLINE_FUNCTION Vec3 damped_velocity(const IntegrateParams& prm, const Vec3& v, const Vec3& x) {
  if (!prm.about_flow) return v;
  const Vec3 d = x - prm.flow_origin;
  return v - Vec3(prm.flow_rate.x * d.x, prm.flow_rate.y * d.y, prm.flow_rate.z * d.z);
}

}  // namespace dem
