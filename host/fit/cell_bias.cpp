#include "host/fit/cell_bias.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "host/util/text_format.hpp"

namespace dem {

Real cell_bias_extrapolation(Real n, Real factor, Real m) {
  const Real a = kCellBiasExponent;
  const Real to_data = std::isfinite(m) && m > 0 ? 1 - std::pow(n / m, a) : 1;
  return std::fabs(to_data) / (1 - std::pow(factor, -a));
}

Real cell_bias_sd(Real diff, Real diff_var, Real extrapolation) {
  if (!std::isfinite(diff)) return 0;
  return extrapolation * std::sqrt(std::max(Real(0), diff * diff - diff_var));
}

CellBias measure_cell_bias(PeriodicLab& lab, const Model& base, const std::vector<TriaxialTest>& measured,
                           const Ensemble& reference, const Misfit& misfit) {
  // Data from specimens of the cell's own balls leave no size to extrapolate to: every bias the check could measure
  // would be counted times zero (cell_bias_extrapolation), so it is not run.
  const Real balls = static_cast<Real>(lab.balls());
  if (std::all_of(measured.begin(), measured.end(), [&](const TriaxialTest& t) {
        return cell_bias_extrapolation(balls, kCellCheckFactor, t.specimen_balls) == 0;
      })) {
    CellBias none;
    for (std::size_t k = 0; k < measured.size(); ++k) none.sd.emplace_back(misfit.features(k).size(), Real(0));
    none.note = fmt("the simulator's cell has the balls of the data's specimens (%.0f)", balls) +
                ": no size to extrapolate its bias to, so the cell's check (cells of 4 times the balls) was not run";
    return none;
  }
  // Prepared as the simulator's specimens are: to the data's void ratio where they give one (on this cell's own
  // preparation friction), else with the same preparation.
  // The mean matched is the check cells' own (their first kStateMatchSpecimens).
  StateMatch state;
  MatchPlan plan;
  plan.first_seed = lab.config().run.seed + kCellCheckSeedOffset;
  plan.steps = kCellCheckPrepSteps;
  plan.workers = lab.workers();
  // The lab's cell was matched to the same data: the larger one's friction lies near its own.
  plan.around = std::sqrt(lab.config().periodic.prep_mu_s);
  plan.store = lab.run_store();
  const Config bigger = larger_cell(lab.config(), kCellCheckFactor);
  if (lab.verbose())
    std::printf("triaxdem: the cell's bias check: %d cells of %ld balls at the base model, %zu tests each%s\n",
                kCellCheckSpecimens, bigger.particles.count, measured.size(),
                std::any_of(measured.begin(), measured.end(),
                            [](const TriaxialTest& t) { return std::isfinite(t.void_ratio); })
                    ? ", prepared to the data's void ratio"
                    : "");
  const Config cfg = matched_state(bigger, measured, state, lab.verbose(), plan);
  PeriodicLab check(cfg, lab.verbose(), kCellCheckSpecimens, plan.first_seed, kCellCheckSpecimens, lab.workers());
  check.set_run_store(lab.run_store());  // its own specimens: their runs have their own names there
  check.set_q_measure(lab.q_measure());
  if (lab.verbose()) check.set_progress("triaxdem: the cell's bias check");
  const Ensemble larger = check.run_ensemble(base, measured, true);
  const Real n = static_cast<Real>(lab.balls()), factor = static_cast<Real>(check.balls()) / n;
  std::vector<std::vector<Real>> sd(measured.size());
  std::vector<Real> share;  // the bias over the data's noise, for the note
  for (std::size_t k = 0; k < measured.size(); ++k) {
    const std::vector<Real> small = misfit.mean_values(k, reference[k]), big = misfit.mean_values(k, larger[k]);
    const Real s = static_cast<Real>(reference[k].size()), sc = static_cast<Real>(larger[k].size());
    const Real g = cell_bias_extrapolation(n, factor, measured[k].specimen_balls);
    for (std::size_t i = 0; i < small.size(); ++i) {
      const Feature& f = misfit.features(k)[i];
      // Both means scatter as the simulator's specimens do, the larger cells' less by the size law of the scatter.
      const Real var = f.ensemble_sd * f.ensemble_sd * (1 / s + std::pow(factor, -2 * kSpecimenScatterExponent) / sc);
      sd[k].push_back(cell_bias_sd(big[i] - small[i], var, g));
      const Real data = f.data_noise();
      if (data > 0) share.push_back(sd[k].back() / data);
    }
  }
  std::sort(share.begin(), share.end());
  const Real median = share.empty() ? 0 : share[share.size() / 2], top = share.empty() ? 0 : share.back();
  std::string note = fmt("the simulator's cell: %.0f cells of ", static_cast<double>(kCellCheckSpecimens)) +
                     fmt("%.0f balls", factor * n) +
                     " at the base model" +
                     (state.tests > 0 ? fmt(" (prepared to e = %.4f", state.target) + fmt(", reached %.4f)", state.reached)
                                      : std::string()) +
                     fmt(" differ from the %.0f scatter specimens beyond their own scatter by ", static_cast<Real>(reference.front().size())) +
                     fmt("%.2f of the data's noise (median; at most ", median) + fmt("%.2f),", top) +
                     " extrapolated to the data's specimen size and counted as noise";
  return {sd, note};
}

}  // namespace dem
