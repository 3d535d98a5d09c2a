#pragma once
/// A laboratory's noise models: how one specimen's test scatters about the population's, for data that carry no
/// noise of their own or when the user asks for a lab's (`--noise lab`, `--noise FILE`). Free of Kokkos and
/// Eigen, so that the config reader fills them from a file (read_lab_noise).
#include <array>
#include <string>

#include "kernels/core/real.hpp"

namespace dem {

enum Quantity : int { kInitialStiffness = 0, kEarly, kMid, kPeak, kStrainAtPeak, kResidual, kDilatancy, kQuantities };

/// Name of a quantity in tables and files ("E_ini", "q_peak", ...).
const char* quantity_name(int q);

/// Lab noise of the summary quantities: s_q = max(rel_q |measured|, abs_q), of which a specimen factor of
/// standard deviation `specimen` is shared by the stresses of one test (a denser specimen raises them all):
///   C = diag(s_q^2 - (specimen m_q)^2) + specimen^2 m m^T,   m_q = measured stress quantity (0 for the others).
struct NoiseModel {
  std::array<Real, kQuantities> rel{0.10, 0.06, 0.06, 0.04, 0.0, 0.05, 0.20};
  std::array<Real, kQuantities> abs{0.0, 0.0, 0.0, 0.0, 0.02, 0.0, 0.05};
  Real specimen = 0.02;
  Real sigma(int q, Real measured) const;
  static bool is_stress(int q);
};

/// Lab noise of curve features: q scatters by `q_rel` of its value about the population's curve, of which
/// `q_shared` is one factor for the whole curve (a denser specimen); eps_v by max(ev_rel |eps_v|, ev_abs).
/// Both correlated along strain with length `length` in ln(strain).
struct LabCurveNoise {
  Real q_rel = 0.05, q_shared = 0.02, ev_rel = 0.10, ev_abs = 5e-4, length = 1.0;
};

/// Both lab models as a file gives them (configs/calibration/lab_noise.toml shows every key with the defaults).
struct LabNoise {
  LabCurveNoise curve;
  NoiseModel summary;
};
/// Reads a lab noise file; a missing file, an unknown key or a value out of range is a ConfigError naming the
/// file, the key and the allowed range. Defined beside the config reader, which owns the TOML parser.
LabNoise read_lab_noise(const std::string& path);

}  // namespace dem
