/// The noise budget of a material's data, decided once (host/fit/misfit.hpp, decide_noise_budget): the simulator's
/// scatter at the base, the ensemble and the cell an "auto" setting chooses from it, and the cell's bias.
#include <algorithm>

#include "host/fit/cell_bias.hpp"
#include "host/fit/misfit.hpp"

namespace dem {

NoiseBudget decide_noise_budget(PeriodicLab& lab, const Model& base, const std::vector<TriaxialTest>& measured,
                                const NoiseOptions& noise, bool cell_bias, const StateMatch& state) {
  NoiseBudget b;
  b.state = state;
  b.sim_end = lab.config().periodic.triax.target_strain;
  b.scatter = lab.run_ensemble(base, measured, true);
  auto misfit = [&] { return Misfit(measured, noise, b.scatter, lab.members(), b.sim_end, Real(lab.balls())); };
  const bool chosen = lab.config().calibrate.ensemble == kAutoEnsemble;
  // One specimen a point runs each point once: "auto" neither chooses an ensemble nor grows the cell for one.
  if (chosen && lab.config().calibrate.one_specimen()) {
    lab.set_members(1);
  } else if (chosen) {
    lab.set_members(lab.specimens());
    const int wanted = misfit().members_for(kEnsembleRatioGoal);
    // The cap is on the cell, not on one step: a lab shared by several materials may have grown for an earlier one.
    const int room = kMaxCellFactor / lab.cell_factor();
    if (wanted > lab.specimens() && room > 1 && lab.config().calibrate.cell_factor == kAutoCell) {
      b.state = lab.grow_cell(std::min(room, (wanted + lab.specimens() - 1) / lab.specimens()), b.state);
      b.scatter = lab.run_ensemble(base, measured, true);
    }
    lab.set_members(std::min(misfit().members_for(kEnsembleRatioGoal), lab.specimens()));
  }
  b.members = lab.members();
  b.cell_factor = lab.cell_factor();
  b.sim_balls = static_cast<Real>(lab.balls());
  if (cell_bias) b.cell_bias = measure_cell_bias(lab, base, measured, b.scatter, misfit());
  return b;
}

Misfit measure_misfit(PeriodicLab& lab, const Model& base, const std::vector<TriaxialTest>& measured,
                      const NoiseOptions& noise, bool cell_bias, const StateMatch& state) {
  return Misfit(measured, noise, decide_noise_budget(lab, base, measured, noise, cell_bias, state));
}

}  // namespace dem
