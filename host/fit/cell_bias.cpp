#include "host/fit/cell_bias.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

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

namespace {

/// One quantity's bias over its data: each datum's bias over the data's noise, and the difference of the larger
/// cells' mean from the cell's, extrapolated to the data's specimen, summed with the cell's values (table units).
struct QuantityBias {
  std::string name;
  std::vector<Real> share;
  Real diff = 0, cell = 0;
  int n = 0;
  const char* unit = "";
};

QuantityBias& quantity_bias(std::vector<QuantityBias>& by, const std::string& name) {
  for (QuantityBias& q : by)
    if (q.name == name) return q;
  by.push_back({});
  by.back().name = name;
  return by.back();
}

Real median_of(std::vector<Real> v) {
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

/// CellBias::finding: the quantities whose bias exceeds the data's noise at their median, and the cause a cell of
/// `n` balls against data of `data_balls` most likely has.
std::string bias_finding(const std::vector<QuantityBias>& by, bool walls, Real n, Real data_balls) {
  std::string which;
  for (const QuantityBias& q : by) {
    const Real med = median_of(q.share);
    if (med <= 1 || q.n == 0) continue;
    const Real mean = q.diff / q.n, rel = q.cell != 0 ? 100 * q.diff / std::fabs(q.cell) : 0;
    which += (which.empty() ? "" : "; ") + q.name + fmt(": %+.3g ", mean) + q.unit +
             (std::string(q.unit) == "kPa" || std::string(q.unit) == "MPa" ? fmt(" (%+.1f%%)", rel) : std::string()) +
             fmt(", %.2g times the data's noise (median)", med);
  }
  if (which.empty()) return "";
  const std::string size = std::isfinite(data_balls) ? fmt("%.0f", data_balls) + " balls" : "an unlimited size";
  const std::string cause =
      walls ? fmt("the walled cell of %.0f balls is smaller than the data's specimen (", n) + size +
                  "): the walls' looser layer is a larger share of it (the share falls as N^-1/3); matched whole to "
                  "the data's void ratio its interior packs denser than the data's, and matched on its interior the "
                  "layer still carries a larger share of the strain. A walled cell of the data's balls ([particles] "
                  "count) removes it"
            : fmt("a periodic cell of %.0f balls does not respond as a specimen of ", n) + size +
                  " (finite size). A larger cell ([calibrate] cell_factor, or [particles] count) shrinks it";
  return "The simulator's cell differs from a specimen of the data's size by more than the data's noise, the larger "
         "cells' mean extrapolated to the data's size against the cell's: " + which + ". Likely cause: " + cause +
         ". Counted as noise, such a bias lets a wrong model pass as a fit within the noise: read the fit and the "
         "verdict with it.";
}

}  // namespace

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
  const bool walls = lab.config().periodic.boundary == CellBoundary::walls;
  CellBias bias = cell_bias_between(misfit, measured, reference, larger, static_cast<Real>(lab.balls()),
                                    static_cast<Real>(check.balls()) / static_cast<Real>(lab.balls()), walls);
  bias.note = fmt("the simulator's cell: %.0f cells of ", static_cast<double>(kCellCheckSpecimens)) +
              fmt("%.0f balls", static_cast<double>(check.balls())) + " at the base model" +
              (state.tests > 0 ? fmt(" (prepared to e = %.4f", state.target) + fmt(", reached %.4f)", state.reached)
                               : std::string()) +
              bias.note;
  // Matched to the same void ratio, a smaller walled cell needs a lower preparation friction for its looser layer
  // at the walls: the two frictions show how much denser its interior was packed.
  if (state.tests > 0) {
    const std::string frictions =
        fmt("preparation friction to the data's void ratio: %.3g", lab.config().periodic.prep_mu_s) +
        fmt(" in the cell of %.0f balls, ", static_cast<double>(lab.balls())) + fmt("%.3g", cfg.periodic.prep_mu_s) +
        fmt(" in the check's cells of %.0f", static_cast<double>(check.balls()));
    bias.note += "; " + frictions;
    if (!bias.finding.empty()) bias.finding += " The " + frictions + ".";
  }
  return bias;
}

CellBias cell_bias_between(const Misfit& misfit, const std::vector<TriaxialTest>& measured, const Ensemble& reference,
                           const Ensemble& larger, Real n, Real factor, bool walls) {
  std::vector<std::vector<Real>> sd(measured.size());
  std::vector<Real> share;  // the bias over the data's noise, for the note
  std::vector<QuantityBias> by;  // per quantity, for the finding
  Real data_balls = 0;           // the data's largest specimen (infinite: not given)
  for (std::size_t k = 0; k < measured.size(); ++k) {
    const std::vector<Real> small = misfit.mean_values(k, reference[k]), big = misfit.mean_values(k, larger[k]);
    const Real s = static_cast<Real>(reference[k].size()), sc = static_cast<Real>(larger[k].size());
    const Real g = cell_bias_extrapolation(n, factor, measured[k].specimen_balls);
    const Real m = measured[k].specimen_balls;
    data_balls = std::max(data_balls, std::isfinite(m) && m > 0 ? m : std::numeric_limits<Real>::infinity());
    for (std::size_t i = 0; i < small.size(); ++i) {
      const Feature& f = misfit.features(k)[i];
      // Both means scatter as the simulator's specimens do, the larger cells' less by the size law of the scatter.
      const Real var = f.ensemble_sd * f.ensemble_sd * (1 / s + std::pow(factor, -2 * kSpecimenScatterExponent) / sc);
      sd[k].push_back(cell_bias_sd(big[i] - small[i], var, g));
      const Real data = f.data_noise();
      if (data > 0) share.push_back(sd[k].back() / data);
      QuantityBias& q = quantity_bias(by, quantity_group(f));
      if (data > 0) q.share.push_back(sd[k].back() / data);
      if (std::isfinite(big[i]) && std::isfinite(small[i])) {
        q.unit = feature_unit(f, 1).second;
        q.diff += feature_unit(f, g * (big[i] - small[i])).first;
        q.cell += feature_unit(f, small[i]).first;
        ++q.n;
      }
    }
  }
  std::sort(share.begin(), share.end());
  const Real median = share.empty() ? 0 : share[share.size() / 2], top = share.empty() ? 0 : share.back();
  const std::string note =
      fmt(" differ from the %.0f scatter specimens beyond their own scatter by ", static_cast<Real>(reference.front().size())) +
      fmt("%.2f of the data's noise (median; at most ", median) + fmt("%.2f),", top) +
      " extrapolated to the data's specimen size and counted as noise";
  return {sd, note, bias_finding(by, walls, n, data_balls)};
}

}  // namespace dem
