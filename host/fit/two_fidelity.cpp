#include "host/fit/two_fidelity.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "host/triax/specimen.hpp"
#include "host/util/text_format.hpp"

namespace dem {

namespace {

/// Per feature: the sample variance of the members' values about their mean, over the members that have one.
std::vector<Real> sample_variance(const Misfit& misfit, std::size_t k, const std::vector<TriaxialTest>& members,
                                  const std::vector<Real>& mean) {
  std::vector<Real> sum(mean.size(), 0);
  std::vector<int> n(mean.size(), 0);
  for (const TriaxialTest& t : members) {
    const std::vector<Real> v = misfit.mean_values(k, {t});
    for (std::size_t f = 0; f < v.size(); ++f)
      if (std::isfinite(v[f])) sum[f] += (v[f] - mean[f]) * (v[f] - mean[f]), ++n[f];
  }
  for (std::size_t f = 0; f < sum.size(); ++f) sum[f] = n[f] > 1 ? sum[f] / (n[f] - 1) : 0;
  return sum;
}

}  // namespace

Config reference_cell(const Config& base, const std::string& cli) {
  Config c = base;
  if ((cli.empty() ? base.calibrate.reference_test : cli) == "walls") {
    c.periodic.boundary = CellBoundary::walls;
  } else if (!cli.empty()) {  // --reference-test periodic (or two_fidelity) asks for the periodic cell by name
    c.periodic.boundary = CellBoundary::periodic;
    c.box.periodic = {true, true, true};
  }
  return c;
}

bool two_fidelity_wanted(const Config& base, const std::string& cli, bool membrane) {
  if ((cli.empty() ? base.calibrate.reference_test : cli) != "two_fidelity") return false;
  const std::string key = cli.empty() ? base.path + ": [calibrate] reference_test" : "--reference-test";
  if (!membrane) throw ConfigError(key + ": two_fidelity needs a membrane test: [calibrate] predict or --predict");
  if (base.calibrate.predict_specimens < 2)
    throw ConfigError(base.path + ": [calibrate] predict_specimens: two_fidelity measures the discrepancy's scatter "
                      "on the membrane specimens (allowed: 2-16)");
  return true;
}

void check_template_law(const Config& base, const Config& membrane, const std::string& key) {
  const int a = static_cast<int>(base.ball.law), b = static_cast<int>(membrane.ball.law);
  if (a != b)
    throw ConfigError(key + ": two fidelities correct the cell toward the membrane test of " + membrane.path +
                      ", whose contact law is " + kContactLawNames[b] + " where the base's (" + base.path + ") is " +
                      kContactLawNames[a] + ": give the template the base's [material] law");
}

void check_template_size(const Config& membrane, const std::vector<TriaxialTest>& tests, const std::string& key) {
  const Real balls = static_cast<Real>(specimen_ball_count(membrane));
  for (const TriaxialTest& t : tests)
    if (std::isfinite(t.specimen_balls) && std::fabs(balls / t.specimen_balls - 1) > kTemplateSizeTolerance)
      throw ConfigError(key + ": two fidelities correct the cell toward the membrane test of " + membrane.path + ", " +
                        fmt("whose specimen has %.0f balls", balls) + " where the data's (" + t.material +
                        fmt(" at %g kPa) have ", 1e-3 * t.sigma3) + fmt("%.0f", t.specimen_balls) +
                        fmt(": the template must be the data's size within %.0f%%", 100 * kTemplateSizeTolerance) +
                        " (a template of the data's specimen, or --reference-test periodic with the prediction alone)");
}

bool scales_with_stress(const Feature& f) {
  if (f.strain > 0) return f.quantity == 0;  // a curve's q (eps_v is quantity 1)
  return f.quantity != kStrainAtPeak && f.quantity != kDilatancy;
}

Discrepancy measure_discrepancy(const Misfit& misfit, const std::vector<Prediction>& membrane,
                                const Ensemble& periodic) {
  if (membrane.size() != misfit.tests() || periodic.size() != misfit.tests())
    throw std::logic_error("two-fidelity: runs for other tests than the misfit's");
  Discrepancy d;
  Ensemble tested;
  for (const Prediction& p : membrane) tested.push_back(p.members);
  d.membrane_chi2 = 0;
  for (Real r : misfit.residuals(tested)) d.membrane_chi2 += r * r;
  for (std::size_t k = 0; k < misfit.tests(); ++k) {
    const std::vector<TriaxialTest>& mem = membrane[k].members;
    if (mem.size() < 2 || periodic[k].size() < 2)
      throw std::invalid_argument("two-fidelity: the discrepancy's scatter needs at least 2 specimens of each test "
                                  "([calibrate] predict_specimens and the ensemble)");
    const std::vector<Real> m = misfit.mean_values(k, mem), p = misfit.mean_values(k, periodic[k]);
    const std::vector<Real> vm = sample_variance(misfit, k, mem, m), vp = sample_variance(misfit, k, periodic[k], p);
    const Real km = static_cast<Real>(mem.size()), kp = static_cast<Real>(periodic[k].size());
    const std::vector<Feature>& fs = misfit.features(k);
    std::vector<Real> delta(m.size(), 0), sd(m.size(), 0);
    for (std::size_t f = 0; f < m.size(); ++f) {
      // A feature one of the tests does not reach (a strain beyond its curve) is left uncorrected, uncounted.
      if (!(std::isfinite(m[f]) && std::isfinite(p[f]))) continue;
      if (scales_with_stress(fs[f]) && m[f] > 0 && p[f] > 0) {
        // The cell reads rho = p / m of the membrane test: the data's value y becomes rho y, delta = (1 - rho) y.
        const Real rho = p[f] / m[f], y = fs[f].measured;
        delta[f] = (1 - rho) * y;
        sd[f] = std::fabs(rho * y) * std::sqrt(vm[f] / (km * m[f] * m[f]) + vp[f] / (kp * p[f] * p[f]));
      } else {
        delta[f] = m[f] - p[f];
        sd[f] = std::sqrt(vm[f] / km + vp[f] / kp);
      }
    }
    d.delta.push_back(delta);
    d.sd.push_back(sd);
  }
  return d;
}

std::string discrepancy_text(const Misfit& misfit, const Discrepancy& d, const std::vector<TriaxialTest>& tests) {
  std::string s;
  for (std::size_t k = 0; k < d.delta.size(); ++k) {
    Real delta = 0, sd = 0, ratio = 0;
    int n = 0;
    const std::vector<Feature>& fs = misfit.features(k);
    for (std::size_t f = 0; f < fs.size(); ++f)
      if (scales_with_stress(fs[f]) && (fs[f].strain > 0 || fs[f].quantity != kInitialStiffness) &&
          fs[f].measured != 0) {
        delta += d.delta[k][f];
        sd += d.sd[k][f];
        ratio += 1 - d.delta[k][f] / fs[f].measured;
        ++n;
      }
    if (n == 0) continue;
    s += tests[k].material + fmt(" at %g kPa: the periodic cell reads ", 1e-3 * tests[k].sigma3) +
         fmt("%.3f of the membrane test's q", ratio / n) + fmt("; the data's q taken down by %.1f", 1e-3 * delta / n) +
         fmt(" +- %.1f kPa (mean over ", 1e-3 * sd / n) + std::to_string(n) + " compared q values)\n";
  }
  return s;
}

namespace {

/// The parameters of `r` in words with their intervals: "mu_s 0.105 [0.085, 0.189], mu_r 0.05 [0, 0.06]".
std::string values_text(const CalibrationResult& r) {
  std::string s;
  for (std::size_t k = 0; k < r.free.size(); ++k) {
    const Real f = r.free[k].shown;
    s += (k ? ", " : "") + r.free[k].name + fmt(" %.4g", f * r.values[k]) + fmt(" [%.4g", f * r.interval[k].first) +
         fmt(", %.4g]", f * r.interval[k].second);
  }
  return s;
}

}  // namespace

namespace {

/// Where round k + 1 measures: the last corrected optimum (the plain iteration), or from the third round on, per
/// parameter, the secant root of the residual g = optimum - at through the last two rounds, where its slope says the
/// iteration contracts (F' = 1 + slope within (-1, 1): a slope outside (-2, 0) is the runs' scatter, not the map);
/// inside the last fit's range. `secant` says whether any parameter took the secant step.
std::vector<Real> next_at(const std::vector<FidelityRound>& rounds, bool& secant) {
  const FidelityRound& b = rounds.back();
  std::vector<Real> at = b.fit.values;
  secant = false;
  if (rounds.size() < 2) return at;
  const FidelityRound& a = rounds[rounds.size() - 2];
  for (std::size_t k = 0; k < at.size(); ++k) {
    const Real ga = a.fit.values[k] - a.at[k], gb = b.fit.values[k] - b.at[k], dx = b.at[k] - a.at[k];
    if (dx == 0) continue;
    const Real slope = (gb - ga) / dx;
    if (!(slope > -2 && slope < 0)) continue;
    at[k] = std::clamp(b.at[k] - gb / slope, b.fit.free[k].lo, b.fit.free[k].hi);
    secant = true;
  }
  return at;
}

}  // namespace

std::size_t membrane_choice(const std::vector<FidelityRound>& rounds, Real last_chi2) {
  std::size_t best = rounds.size();
  Real chi2 = last_chi2;
  for (std::size_t i = 0; i < rounds.size(); ++i)
    if (rounds[i].membrane_chi2 < chi2 || (!std::isfinite(chi2) && std::isfinite(rounds[i].membrane_chi2)))
      best = i, chi2 = rounds[i].membrane_chi2;
  return best;
}

FidelityRounds two_fidelity_rounds(const CalibrationResult& periodic, const Misfit& misfit,
                                   const std::vector<TriaxialTest>& tests, const DiscrepancyAt& measure,
                                   const CalibrateTo& fit, const std::string& template_path, int max_rounds,
                                   const EvaluateAt& evaluate) {
  FidelityRounds out;
  Misfit corrected = misfit;
  for (int round = 1; round <= max_rounds && !out.converged; ++round) {
    FidelityRound r;
    Model at = periodic.model;
    if (out.rounds.empty()) {
      r.at = periodic.values;
    } else {
      r.at = next_at(out.rounds, r.secant);
      at = out.rounds.back().fit.model;
      for (std::size_t k = 0; k < r.at.size(); ++k) set_param(at, periodic.free[k].name, r.at[k]);
    }
    // Always the data as measured less this round's discrepancy: each round replaces the last one's correction.
    const Discrepancy d = measure(at);
    r.discrepancy = discrepancy_text(misfit, d, tests);
    r.membrane_chi2 = d.membrane_chi2;
    corrected = misfit;
    corrected.add_discrepancy(d.delta, d.sd, "two fidelities, round " + std::to_string(round) +
                                                 ": the data less the membrane test's excess over the periodic cell "
                                                 "at the last optimum (" + template_path + "), with its standard error");
    r.fit = fit(corrected);
    // The fixed point's residual: how far the optimum lies from where its discrepancy was measured, in the joint
    // region's metric: a rise of the surrogate chi2 by (distance / radius)^2 of the region's, the width two radii.
    // Along a ridge the data leave free (S-1: three peaks, two parameters) a move costs nothing and is no change.
    r.moved = std::sqrt(std::max(Real(0), r.fit.region_rise(r.at))) / 2;
    out.converged = r.moved < kFixedPointMove;
    out.rounds.push_back(std::move(r));
  }
  if (out.rounds.empty()) return out;
  out.answer = out.rounds.back().fit;
  out.chosen = out.rounds.size();
  if (out.converged || !evaluate) return out;
  out.last_membrane_chi2 = measure(out.answer.model).membrane_chi2;
  out.chosen = membrane_choice(out.rounds, out.last_membrane_chi2);
  if (out.chosen < out.rounds.size()) {
    // The chosen round's point with the periodic cell's values and intervals there, against the last correction.
    const std::vector<Real>& at = out.rounds[out.chosen].at;
    Model m = out.answer.model;
    for (std::size_t k = 0; k < at.size(); ++k) set_param(m, out.answer.free[k].name, at[k]);
    Evaluation e = evaluate(m, corrected);
    e.u.clear();
    for (std::size_t k = 0; k < at.size(); ++k) e.u.push_back(out.answer.free[k].unit(at[k]));
    adopt_best(out.answer, e, m);
  }
  return out;
}

std::string FidelityRounds::text() const {
  std::string s;
  for (std::size_t i = 0; i < rounds.size(); ++i) {
    const FidelityRound& r = rounds[i];
    s += "Round " + std::to_string(i + 1) + ": the discrepancy measured at";
    for (std::size_t k = 0; k < r.at.size(); ++k)
      s += (k ? ", " : " ") + r.fit.free[k].name + fmt(" = %.4g", r.fit.free[k].shown * r.at[k]);
    s += std::string(r.secant ? " (a secant step through the last two rounds)" : "") + ":\n\n" + r.discrepancy + "\nthe corrected optimum: " + values_text(r.fit) +
         fmt(", chi2 %.1f", r.fit.best.chi2) +
         fmt("; it lies %.2f", r.moved) + " of the joint 95% region's width from where the discrepancy was measured" +
         ".\n\n";
  }
  if (rounds.empty()) return s;
  const std::string n = std::to_string(rounds.size()) + (rounds.size() == 1 ? " round" : " rounds");
  s += converged ? "The optimum reached its fixed point after " + n +
                       fmt(" (it lies less than %.2f", kFixedPointMove) +
                       " of its region's width from where its discrepancy was measured).\n"
                 : "Not converged: after " + n +
                       fmt(" the optimum still lies %.2f", rounds.back().moved) +
                       " of its region's width from where its discrepancy was measured; " +
                       (std::isfinite(last_membrane_chi2)
                            ? std::string("the membrane test chose the answer (below)")
                            : std::string("the last round's is reported, and the membrane prediction at it shows how "
                                          "far it holds")) + ".\n";
  if (!std::isfinite(last_membrane_chi2)) return s;
  s += "\nThe membrane test itself, by its chi2 against the data as measured, at the points it ran:";
  for (std::size_t i = 0; i < rounds.size(); ++i)
    s += " round " + std::to_string(i + 1) + fmt("'s point %.1f;", rounds[i].membrane_chi2);
  s += fmt(" the last optimum %.1f. ", last_membrane_chi2) +
       (chosen == rounds.size() ? std::string("The last optimum stands.\n")
                                : "Round " + std::to_string(chosen + 1) + "'s point is the answer: " +
                                      values_text(answer) + fmt(" (the cell's chi2 there %.1f", answer.best.chi2) +
                                      " against the last correction).\n");
  return s;
}

}  // namespace dem
