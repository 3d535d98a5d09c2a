#pragma once
/// Centred-difference (leapfrog) integration as in PFC, with gravity and local (Cundall) damping:
///   F_d = -alpha |F| sign(v), component-wise on forces and on moments (PFC manual; sign(0) = 0),
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

}  // namespace dem
