#include "host/config/noise_model.hpp"

#include <algorithm>
#include <cmath>

namespace dem {

const char* quantity_name(int q) {
  static const char* names[kQuantities] = {"E_ini", "q_1pct", "q_3pct", "q_peak", "eps_a_peak", "q_end",
                                           "max_dilatancy"};
  return names[q];
}

Real NoiseModel::sigma(int q, Real measured) const { return std::max(rel[q] * std::fabs(measured), abs[q]); }

bool NoiseModel::is_stress(int q) { return q != kStrainAtPeak && q != kDilatancy; }

}  // namespace dem
