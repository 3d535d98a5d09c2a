#pragma once
/// Servo control of a rigid wall (PFC's wall servo): the wall velocity is proportional to the stress
/// error, with a gain that makes the wall remove a fraction `relax` of the error per step given the
/// stiffness of the contacts it pushes on:
///   v = G (sigma_target - sigma),   G = relax * A / (k_n N_c dt),   |v| <= v_max
/// (positive v moves the wall into the specimen). With no contacts the wall approaches at v_max.
#include "kernels/core/vec3.hpp"

namespace dem {

struct StressServo {
  Real target = 0;     ///< Pa, compression positive
  Real area = 0;       ///< m^2, loaded area of the wall
  Real relax = 0.1;    ///< fraction of the stress error removed per step (0 < relax < 1 for stability)
  Real v_max = 0.1;    ///< m/s

  /// Speed into the specimen (m/s) for the measured stress (Pa) and the wall's contact stiffness sum (N/m).
  Real speed(Real sigma, Real stiffness_sum, Real dt) const;
};

}  // namespace dem
