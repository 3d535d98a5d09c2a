#include "host/triax/periodic_triaxial.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "host/triax/cell_boundary.hpp"
#include "host/triax/periodic_stages.hpp"
#include "kernels/contact/contact_sums.hpp"
#include "kernels/core/reduce.hpp"

namespace dem {

PeriodicTriaxialParams resolve_periodic_params(Simulation& sim, PeriodicTriaxialParams prm) {
  auto bad = [](const std::string& what) { throw std::invalid_argument("periodic triaxial: " + what); };
  const Domain& dom = sim.domain();
  const bool periodic = dom.periodic[0] && dom.periodic[1] && dom.periodic[2];
  if (!periodic && !walled(sim)) bad("the cell must be periodic along x, y and z, or lie between six walls");
  if ((periodic && sim.num_walls() > 0) || sim.membrane().ntri > 0)
    bad("a periodic cell must have no walls, facets or membrane");
  if (norm2(sim.params().integ.gravity) != 0) bad("gravity must be zero in a fully periodic cell");
  if (sim.params().integ.dt <= 0) bad("the time step is not set");
  if (!(prm.sigma3 > 0)) bad("sigma3 must be > 0");
  if (!(prm.target_strain > 0 && prm.target_strain < 0.9)) bad("target axial strain must be in (0, 0.9)");
  if (!(prm.servo_alpha > 0 && prm.servo_alpha <= 1)) bad("servo alpha must be in (0, 1]");
  if (!(prm.stress_tolerance > 0 && prm.unbalanced_tolerance > 0)) bad("tolerances must be > 0");
  if (!(prm.record_strain > 0)) bad("record strain interval must be > 0");
  if (prm.axial_rate < 0 || prm.max_lateral_rate < 0 || prm.consolidation_rate < 0 || prm.gas_rate < 0)
    bad("rates must be >= 0");
  if (!(prm.gas_solid_fraction > 0 && prm.gas_solid_fraction <= kGasSolidFractionMax))
    bad("the gas phase's solid fraction must be in (0, " + std::to_string(kGasSolidFractionMax) + "]");
  if (prm.check_every < 1 || prm.stiffness_every < 1 || prm.max_consolidation_steps < 1)
    bad("check_every, stiffness_every and max_consolidation_steps must be >= 1");
  const GrainScales g = grain_scales(sim);
  const Real scale = g.d * std::sqrt(g.rho_eff / prm.sigma3);  // I = rate * scale at p = sigma3
  if (prm.axial_rate == 0) {
    if (!(prm.target_inertial > 0)) bad("target inertial number must be > 0 when the axial rate is automatic");
    prm.axial_rate = prm.target_inertial / scale;
  }
  const Real inertial = prm.axial_rate * scale;
  if (inertial > prm.max_inertial && !prm.allow_high_inertial) {
    std::ostringstream s;
    s << "axial strain rate " << prm.axial_rate << " /s gives an inertial number I = " << inertial
      << " at p = sigma3, above the quasi-static limit " << prm.max_inertial << " (d = " << g.d
      << " m, rho_eff = " << g.rho_eff << " kg/m^3); lower the rate to at most " << prm.max_inertial / scale
      << " /s or set allow_high_inertial";
    bad(s.str());
  }
  if (prm.max_lateral_rate == 0) prm.max_lateral_rate = 5 * prm.axial_rate;
  if (prm.consolidation_rate == 0) prm.consolidation_rate = prm.max_lateral_rate;
  // Between walls the gas is struck by the walls, which move at the rate times half the cell: no faster gas phase
  // unless asked for (at 4x the walled cell's Z moved by 1.3 seeds' SDs, docs/performance.md).
  if (prm.gas_rate == 0) prm.gas_rate = walled(sim) ? prm.consolidation_rate : kGasRateFactor * prm.consolidation_rate;
  prm.gas_volume = g.v_solid / prm.gas_solid_fraction;
  return prm;
}

StageEnd consolidate_isotropic(Simulation& sim, const PeriodicTriaxialParams& prm_in) {
  const PeriodicTriaxialParams prm = resolve_periodic_params(sim, prm_in);  // idempotent
  const auto cell = cell_of(sim);
  Consolidation stage(*cell, prm);
  StageEnd end = run_stage(sim, stage.steps(), nullptr);
  const std::string failure = stage.end(end);
  if (!failure.empty()) throw std::runtime_error(failure);
  return end;
}

PeriodicTriaxialResult run_periodic_triaxial(Simulation& sim, const PeriodicTriaxialParams& prm_in, io::Output* out) {
  const auto t0 = std::chrono::steady_clock::now();
  GrainScales g;
  PeriodicTriaxialResult res = start_result(sim, prm_in, g);
  const StageEnd consolidated = consolidate_isotropic(sim, res.params);
  res.consolidation_steps = consolidated.step;
  res.stages.push_back(consolidated.timing);
  const auto cell = cell_of(sim);
  Shear shear(*cell, res, g, out, &sim);
  const StageTiming sheared = run_stage(sim, shear.steps(), nullptr).timing;
  shear.end(sheared, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  return res;
}

}  // namespace dem
