#pragma once
/// Servo control of a rigid wall (PFC's wall servo): the wall velocity is proportional to the stress error, with a gain
/// that makes the wall remove a fraction `relax` of the error per step given the stiffness of the contacts it pushes
/// on:
///   v = G (sigma_target - sigma),   G = relax * A / (k_n N_c dt),   |v| <= v_max
/// (positive v moves the wall into the specimen). With no contacts the wall approaches at v_max. The host's servo and
/// the one on the device (a Simulation's: host/engine/simulation.hpp, set_wall_servo) both take the speed from here.
#include "kernels/core/types.hpp"
#include "kernels/core/vec3.hpp"

namespace dem {

struct StressServo {
  Real target = 0;     ///< Pa, compression positive
  Real area = 0;       ///< m^2, loaded area of the wall
  Real relax = 0.1;    ///< fraction of the stress error removed per step (0 < relax < 1 for stability)
  Real v_max = 0.1;    ///< m/s

  /// Speed into the specimen (m/s) for the measured stress (Pa) and the wall's contact stiffness sum (N/m).
  KOKKOS_INLINE_FUNCTION Real speed(Real sigma, Real stiffness_sum, Real dt) const {
    if (stiffness_sum <= 0) return v_max;
    const Real g = relax * area / (stiffness_sum * dt);
    const Real v = g * (target - sigma);
    return v < -v_max ? -v_max : (v_max < v ? v_max : v);
  }
};

/// A stress servo on wall `wall`, which moves along axis `axis` into the specimen towards `sign` (+1 or -1): the
/// stress it measures is -sign times the balls' force on it along the axis over the area, the stiffness sum its
/// touching contacts times `kn` (N/m). The nodes `tied` (a membrane's end ring) move with it.
struct WallServoSpec {
  StressServo servo;
  int wall = 0;
  int axis = 2;
  Real sign = -1;
  Real kn = 0;
  ConstIndexView tied;
};

/// Before a step: the wall's velocity, and its tied nodes', from its load (loads(wall); none where `no_contacts`,
/// before the first contact detection); the wall's speed (m/s) to `speed`, in device memory. One launch.
void wall_servo_velocity(const WallServoSpec& spec, const WallLoadView& loads, bool no_contacts,
                         const Vec3View& wall_velocity, const Vec3View& node_velocity, Real dt, Real* speed);

}  // namespace dem
