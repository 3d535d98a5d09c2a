#include "host/engine/servo.hpp"

#include <algorithm>

namespace dem {

Real StressServo::speed(Real sigma, Real stiffness_sum, Real dt) const {
  if (stiffness_sum <= 0) return v_max;
  const Real g = relax * area / (stiffness_sum * dt);
  return std::clamp(g * (target - sigma), -v_max, v_max);
}

}  // namespace dem
