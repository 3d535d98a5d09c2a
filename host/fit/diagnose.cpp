#include "host/fit/diagnose.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <limits>
#include <map>
#include <random>
#include <sstream>
#include <stdexcept>
#include <type_traits>

#include "host/io/io_hdf5.hpp"
#include "host/util/progress.hpp"
#include "host/util/text_format.hpp"

namespace dem {

namespace {

constexpr Real kZ99 = 2.326;   // standard normal score of the 99% quantile
constexpr Real kTieBIC = 2;     // ... below 2, not worth more than a bare mention

/// A residual model r(u) over unit coordinates (base parameters, then perhaps the extension's strength).
using ResidualModel = std::function<std::vector<Real>(const std::vector<Real>&)>;

/// Held-out chi2: for each held-out part of the data (heldout_parts: each test, or a single test's two halves), the
/// surrogate minimised on the rest gives the parameters, and a run of the simulator with them predicts the part (a
/// run, not the surrogate: the verdict rests on it). NaN where the data have no part to hold out.
Real heldout_chi2(const ResidualModel& model, int d, const std::vector<TriaxialTest>& measured,
                  const std::function<Model(const std::vector<Real>&)>& model_at, PeriodicLab& lab,
                  const Misfit& misfit) {
  const HeldOutParts held = heldout_parts(misfit);
  if (held.parts.empty()) return std::numeric_limits<Real>::quiet_NaN();
  Real total = 0;
  for (const HeldOutPart& part : held.parts) {
    const auto fit = minimise_unit_box([&](const std::vector<Real>& u) {
      const std::vector<Real> r = model(u);
      return sum_sq(r) - sum_sq(r, part.global);
    }, d);
    total += sum_sq(misfit.test_residuals(part.test, lab.run_ensemble(model_at(fit), {measured[part.test]}).front()),
                    part.local);
  }
  return total;
}

Real bic(Real chi2, int k, int n) { return chi2 + k * std::log(static_cast<Real>(n)); }

std::vector<Real> evaluate_surfaces(const std::vector<QuadraticSurface>& s, const std::vector<Real>& u) {
  std::vector<Real> r;
  for (const QuadraticSurface& q : s) r.push_back(q(u));
  return r;
}

/// The strength coordinate t of unit coordinate u: [0, 3] from off, or [1, 3] for an extension that is not
/// the limit of a vanishing parameter (Hertz: delta_ref -> 0 is infinitely stiff, not linear).
Real strength_coordinate(const Extension& e, Real u) { return e.from_off ? 3 * u : 1 + 2 * u; }

/// Extension parameter at strength coordinate t in [0, 3]: off at 0, levels[k-1] at k, geometric between levels.
Real strength_at(const Extension& e, Real t) {
  if (t <= 1) return t * e.levels[0];
  const int k = std::min(static_cast<int>(t), 2);
  return e.levels[k - 1] * std::pow(e.levels[k] / e.levels[k - 1], t - k);
}

/// What an extension's fit needs of the diagnosis: the base fit, its surfaces as a model of the residuals, the
/// base model at unit coordinates, the simulator and the misfit.
struct FitContext {
  PeriodicLab& lab;
  const CalibrationResult& base;
  const std::function<std::vector<Real>(const std::vector<Real>&)>& base_model;
  const std::function<Model(const std::vector<Real>&)>& base_at;
  const std::vector<TriaxialTest>& measured;
  const Misfit& misfit;
  const std::function<void()>& report;  ///< a progress line after each batch of runs
};

/// One extension fitted jointly with the base parameters: its effect measured at the base optimum strength by
/// strength, added to the base surfaces, and the joint optimum run twice (the surrogate corrected by each run).
/// `base_runs` gets any run at strength 0 that beats it (a run of the base model).
ExtensionFit fit_extension(const Extension& e, const FitContext& cx, Evaluation& base_runs) {
  PeriodicLab& lab = cx.lab;
  const std::vector<FreeParam>& free = cx.base.free;
  const int d = static_cast<int>(free.size()), n = cx.base.data;
  ExtensionFit f;
  f.ext = e;
  const long runs0 = lab.runs();
  // The extension's effect at the base optimum, strength by strength.
  std::vector<std::vector<Real>> effect{std::vector<Real>(cx.base.best.r.size(), 0.0)};
  for (Real level : e.levels) {
    Model m = cx.base.model;
    set_param(m, e.param, level);
    const std::vector<Real> r = cx.misfit.residuals(lab.run_ensemble(m, cx.measured));
    cx.report();
    std::vector<Real> diff(r.size());
    for (std::size_t i = 0; i < r.size(); ++i) diff[i] = r[i] - cx.base.best.r[i];
    effect.push_back(diff);
  }
  std::vector<Real> correction(cx.base.best.r.size(), 0.0);
  auto joint = [&](const std::vector<Real>& u) {
    const std::vector<Real> ub(u.begin(), u.begin() + d);
    std::vector<Real> r = cx.base_model(ub);
    const Real t = strength_coordinate(e, u[d]);
    const int k = std::min(static_cast<int>(t), 2);
    const Real w = t - k;
    for (std::size_t i = 0; i < r.size(); ++i)
      r[i] += (1 - w) * effect[k][i] + w * effect[k + 1][i] + correction[i];
    return r;
  };
  auto model_at = [&](const std::vector<Real>& u) {
    Model m = cx.base_at(u);
    set_param(m, e.param, strength_at(e, strength_coordinate(e, u[d])));
    return m;
  };
  // The base model is the extension at strength 0: its best run is the starting point, so an extended fit
  // is never reported worse than the base.
  f.best = cx.base.best;
  std::vector<Real> best_u = cx.base.best.u;
  best_u.push_back(0);
  bool extended = false;  // a run of the extension beat the base
  for (int round = 0; round < 2; ++round) {
    const std::vector<Real> u = minimise_unit_box([&](const std::vector<Real>& x) { return sum_sq(joint(x)); },
                                                  d + 1);
    const std::vector<Real> predicted = joint(u);
    Evaluation ev;
    ev.u.assign(u.begin(), u.begin() + d);
    const Ensemble ens = lab.run_ensemble(model_at(u), cx.measured);
    for (const auto& members : ens) ev.sim.push_back(mean_curve(members));
    ev.r = cx.misfit.residuals(ens);
    ev.chi2 = sum_sq(ev.r);
    cx.report();
    if (strength_at(e, strength_coordinate(e, u[d])) == 0 && ev.chi2 < base_runs.chi2) base_runs = ev;
    if (ev.chi2 < f.best.chi2) f.best = ev, best_u = u, extended = true;
    for (std::size_t i = 0; i < correction.size(); ++i) correction[i] += ev.r[i] - predicted[i];
  }
  for (int k = 0; k < d; ++k) f.values.push_back(free[k].value(best_u[k]));
  f.strength = extended ? strength_at(e, strength_coordinate(e, best_u[d])) : 0;
  f.values.push_back(f.strength);
  f.bic = bic(f.best.chi2, d + 1, n);
  f.heldout = heldout_chi2(joint, d + 1, cx.measured, model_at, lab, cx.misfit);
  f.runs = lab.runs() - runs0;
  return f;
}

/// A drop in BIC in words whichever its sign, "lower by 12.3" or "higher by 2.2" (a model that fits no better
/// pays for its parameter).
std::string bic_change(Real gain) { return fmt(gain >= 0 ? "lower by %.1f" : "higher by %.1f", std::fabs(gain)); }

/// One extension on both tests, against the base model (accepted) and the generic rival where there is one
/// (specific), with its reason in words; `testable`: enough data for an extended model (n >= d + 2).
void weigh(ExtensionFit& f, const Diagnosis& dg, const GenericFit* rival, bool testable) {
  char line[300];
  const Real gain = dg.base_bic - f.bic, held = dg.base_heldout - f.heldout;
  f.accepted = testable && gain >= kStrongEvidence && held >= kStrongEvidence;
  std::snprintf(line, sizeof line, "BIC %s (%s), held-out chi2 %.1f -> %.1f (%s)", bic_change(gain).c_str(),
                gain >= kStrongEvidence ? "passes" : "6 needed",
                dg.base_heldout, f.heldout, held >= kStrongEvidence ? "passes" : "a drop of 6 needed");
  f.reason = std::string(f.accepted ? "accepted: " : "rejected: ") + line;
  if (!rival) {
    f.specific = f.accepted;
    return;
  }
  const Real over = rival->bic - f.bic, over_held = rival->heldout - f.heldout;
  f.specific = f.accepted && over >= kStrongEvidence && over_held >= kStrongEvidence;
  std::snprintf(line, sizeof line, "; against the generic %s: BIC %s, held-out chi2 %.1f -> %.1f (%s)",
                rival->shape.name.c_str(), bic_change(over).c_str(), rival->heldout,
                f.heldout, f.specific ? "specific" : "not specific: a drop of 6 needed in both");
  if (f.accepted) f.reason += line;
}

/// The best generic discrepancy in words, for a verdict that names no extension: the shape of what differs between
/// the data and the base model, with no physics claimed (Brynjarsdottir and O'Hagan 2014: the discrepancy is
/// stated, not explained away).
std::string generic_difference(const Diagnosis& dg, const GenericFit* rival) {
  if (!rival) return "";
  return " The generic discrepancy that fits best is " + rival->shape.name + " (" + rival->shape.formula +
         ", c = " + fmt("%.3g", rival->c) + "): chi2 " + fmt("%.1f", rival->chi2) + ", BIC " +
         bic_change(dg.base_bic - rival->bic) + ", held-out chi2 " + fmt("%.1f", dg.base_heldout) + " -> " +
         fmt("%.1f", rival->heldout) + ".";
}

/// "lowers the held-out chi2 from a to b", or "raises" where it rises: a rival or extension that fits the data
/// better can predict a held-out pressure worse (YADE's linear data: q offset, 51.0 -> 59.6).
std::string heldout_change(double from, double to) {
  return std::string(to <= from ? "lowers" : "raises") + " the held-out chi2 from " + fmt("%.1f", from) + " to " +
         fmt("%.1f", to);
}

/// The explanation of a verdict "none" with enough data to test: candidates (accepted against the base, not against
/// the rival) or no extension accepted at all; either way the generic difference found.
std::string explain_none(const Diagnosis& dg, int n, const std::string& candidates, const ExtensionFit* best_bic,
                         const GenericFit* rival) {
  const bool fits = dg.base.best.chi2 <= dg.chi2_limit;
  char line[600];
  if (!candidates.empty()) {
    std::snprintf(line, sizeof line,
                  "%s (chi2 %.1f on %d data, 99%% limit %.1f), and extensions fit it better (%s), but none more "
                  "specifically than the generic discrepancy %s (%s, c = %.3g), which takes the chi2 to %.1f with a "
                  "BIC %s, and %s: a difference no extension explains specifically. The extensions that "
                  "fit it are candidates, not causes.",
                  fits ? "The base model fits within the noise" : "The base model misses the data", dg.base.best.chi2,
                  n, dg.chi2_limit, candidates.c_str(), rival->shape.name.c_str(), rival->shape.formula.c_str(),
                  rival->c, rival->chi2, bic_change(dg.base_bic - rival->bic).c_str(),
                  heldout_change(dg.base_heldout, rival->heldout).c_str());
    return line;
  }
  std::snprintf(line, sizeof line,
                fits ? "The calibrated base model fits within the data's noise (chi2 %.1f on %d data, below the "
                       "99%% limit %.1f) and no extension passes both tests (the lowest BIC, %s, has a BIC %s "
                       "and %s; a drop of 6 needed for each): no discrepancy beyond noise, and no extension is "
                       "called for."
                     : "The base model misses the data (chi2 %.1f on %d data, 99%% limit %.1f), but no extension "
                       "explains it: none passes both tests (the lowest BIC, %s, has a BIC %s and %s; a "
                       "drop of 6 needed for each).",
                dg.base.best.chi2, n, dg.chi2_limit, best_bic ? best_bic->ext.name.c_str() : "-",
                bic_change(best_bic ? dg.base_bic - best_bic->bic : 0.0).c_str(),
                heldout_change(dg.base_heldout, best_bic ? best_bic->heldout : 0.0).c_str());
  return line + generic_difference(dg, rival);
}

}  // namespace

namespace {
void decide(Diagnosis& dg, int n, int d);
}  // namespace

void give_verdict(Diagnosis& dg, int n, int d) {
  decide(dg, n, d);
  if (!dg.heldout_basis.empty() && !std::isnan(dg.base_heldout))
    dg.explanation += " Held out: " + dg.heldout_basis + ".";
}

namespace {

void decide(Diagnosis& dg, int n, int d) {
  // Verdict. The rule compares nested models (an extension at strength 0 is the base model) and weighs every
  // extension on both tests: a drop of BIC by 6 (a likelihood-ratio test at about 0.3% for 15 data, more
  // powerful than asking whether the base model alone fits within the noise) and a drop of the held-out chi2 by
  // the same 6 (a likelihood ratio of e^3 = 20 on pressures the fit did not see, which guards against an
  // extension that only fits the noise of the pressures it saw). Every extension that passes both is accepted;
  // the verdict names the accepted one of lowest BIC, with the accepted ones within 2 of its BIC as ties.
  const bool fits = dg.base.best.chi2 <= dg.chi2_limit;
  // The rival of every extension: the generic discrepancy of lowest BIC, of the same size. Both hold one parameter
  // by their types; an extension of more (Extension::param a list) stops the build here until generic shapes of
  // its size stand beside it, so that no extension is ever weighed against a smaller rival.
  static_assert(std::is_same_v<decltype(Extension::param), std::string>,
                "an extension with several parameters needs generic rivals of that many (generic_discrepancy.hpp)");
  static_assert(std::is_same_v<decltype(GenericShape::apply), void (*)(TriaxialTest&, Real)>,
                "a generic shape of several parameters is no rival of a one-parameter extension");
  const GenericFit* rival = generic_rival(dg.generic);
  char line[600];
  for (ExtensionFit& f : dg.fits) weigh(f, dg, rival, n >= d + 2);
  const ExtensionFit* top = nullptr;
  for (const ExtensionFit& f : dg.fits)
    if (f.specific && (!top || f.bic < top->bic)) top = &f;
  const ExtensionFit* best_bic = nullptr;  // the candidate a "none" names, to show what it would change
  for (const ExtensionFit& f : dg.fits)
    if (!best_bic || f.bic < best_bic->bic) best_bic = &f;
  if (n < d + 2) {  // an extended model with as many parameters as data fits anything
    dg.verdict = "none";
    std::snprintf(line, sizeof line,
                  "%d data cannot test an extension: the extended model has %d parameters and fits any %d numbers. "
                  "The base model's chi2 is %.1f (99%% limit %.1f); the fits below show what each extension would "
                  "need, not which is right. Curves, or more quantities per test, are needed to name a cause.",
                  n, d + 1, n, dg.base.best.chi2, dg.chi2_limit);
    dg.explanation = line;
    return;
  }
  if (std::isnan(dg.base_heldout) && !dg.heldout_basis.empty()) {  // no part of the data to predict from the rest
    dg.verdict = "none";
    dg.explanation = "No extension can be named: the verdict needs a held-out check, and " + dg.heldout_basis +
                     ". The base model's chi2 is " + fmt("%.1f", dg.base.best.chi2) + " (99% limit " +
                     fmt("%.1f", dg.chi2_limit) + "); the fits below show what each extension would change.";
    return;
  }
  if (!top) {
    std::string candidates;  // accepted against the base model, not against the generic rival
    for (const ExtensionFit& f : dg.fits)
      if (f.accepted && !f.specific) candidates += (candidates.empty() ? "" : ", ") + f.ext.name;
    dg.verdict = "none";
    dg.explanation = explain_none(dg, n, candidates, best_bic, rival);
    return;
  }
  dg.verdict = top->ext.name;
  std::string ties;
  for (const ExtensionFit& f : dg.fits)
    if (&f != top && f.specific && f.bic - top->bic < kTieBIC) {
      dg.verdict += " or " + f.ext.name;
      ties += (ties.empty() ? "" : ", ") + f.ext.name;
    }
  std::snprintf(line, sizeof line,
                "%s (chi2 %.1f on %d data, 99%% limit %.1f). %s (%s = %.3g) explains it: "
                "chi2 %.1f, BIC lower by %.1f, held-out chi2 %.1f -> %.1f. Signature: %s.",
                fits ? "The base model fits within the noise, but a model extension fits significantly better"
                     : "The base model misses the data",
                dg.base.best.chi2, n, dg.chi2_limit, top->ext.name.c_str(), top->ext.param.c_str(),
                free_param(top->ext.param).shown * top->strength, top->best.chi2, dg.base_bic - top->bic,
                dg.base_heldout, top->heldout, top->ext.signature.c_str());
  dg.explanation = line;
  if (!ties.empty())
    dg.explanation += " These data cannot tell it from " + ties + " (both tests passed, BIC within 2).";
  if (rival)
    dg.explanation += " It beats the best generic discrepancy of its size too (" + rival->shape.name + ": BIC " +
                      fmt("%.1f", rival->bic) + " against " + fmt("%.1f", top->bic) + ", held-out chi2 " +
                      fmt("%.1f", rival->heldout) + " against " + fmt("%.1f", top->heldout) + "): its shape is specific.";
}

}  // namespace

namespace {

/// The extension fits worse than a new base fit are at the base point: their values and held-out chi2 are the base's.
void fall_back_to_base(Diagnosis& dg, int d, int n) {
  for (ExtensionFit& f : dg.fits)
    if (f.best.chi2 > dg.base.best.chi2) {
      f.best = dg.base.best;
      f.strength = 0;
      f.values = dg.base.values;
      f.values.push_back(0);
      f.bic = bic(f.best.chi2, d + 1, n);
      f.heldout = dg.base_heldout;
    }
}

}  // namespace

Diagnosis diagnose(PeriodicLab& lab, const Model& base, const std::vector<FreeParam>& free0,
                   const std::vector<TriaxialTest>& measured, const Misfit& misfit, bool verbose) {
  Diagnosis dg;
  const int d = static_cast<int>(free0.size());
  auto say = [&](const char* fmt, auto... a) {
    if (verbose) std::printf(fmt, a...);
  };
  const std::vector<Extension> menu = extensions_of(base, verbose);
  const std::size_t tried = menu.size();
  say("diagnose: calibrating the base model (%d free parameters) on %zu tests, then %zu extensions\n", d,
      measured.size(), tried);
  const long planned =
      static_cast<long>(measured.size()) * lab.members() * (planned_points(d) + static_cast<long>(tried) * 6);
  const long runs0 = lab.runs();
  Progress progress("diagnose", planned);
  Real best_chi2 = 0;
  auto report = [&](Real chi2) {
    if (!verbose) return;
    char extra[64];
    std::snprintf(extra, sizeof extra, "runs, best base chi2 %.1f", chi2);
    progress.update(std::min(lab.runs() - runs0, planned), extra);
  };
  dg.base = calibrate(lab, base, free0, measured, misfit, 4, [&](long, long, Real chi2) { report(best_chi2 = chi2); });
  const std::vector<FreeParam>& free = dg.base.free;  // the ranges as the calibration left them
  const int n = dg.base.data;
  dg.chi2_limit = n > d ? chi2_quantile(n - d, kZ99) : 0;  // no degrees of freedom: any misfit is too much
  dg.base_bic = bic(dg.base.best.chi2, d, n);
  // The base surfaces, shifted to agree with the best run where they are used most (set again where a nested
  // run becomes the base fit, below).
  std::vector<QuadraticSurface> surf = response_surfaces(dg.base.design, dg.base.best.u);
  std::vector<Real> at_best = evaluate_surfaces(surf, dg.base.best.u);
  const std::function<std::vector<Real>(const std::vector<Real>&)> base_model = [&](const std::vector<Real>& u) {
    std::vector<Real> r = evaluate_surfaces(surf, u);
    for (std::size_t i = 0; i < r.size(); ++i) r[i] += dg.base.best.r[i] - at_best[i];
    return r;
  };
  const std::function<Model(const std::vector<Real>&)> base_at = [&](const std::vector<Real>& u) {
    Model m = base;
    for (int k = 0; k < d; ++k) set_param(m, free[k].name, free[k].value(u[k]));
    return m;
  };
  dg.heldout_basis = heldout_parts(misfit).basis;
  dg.base_heldout = heldout_chi2(base_model, d, measured, base_at, lab, misfit);
  say("diagnose: base chi2 %.1f on %d data (99%% limit for noise alone %.1f), held-out chi2 %.1f\n",
      dg.base.best.chi2, n, dg.chi2_limit, dg.base_heldout);

  Evaluation base_runs = dg.base.best;  // the best run of the base model, also among the extension fits' runs
  const std::function<void()> report_runs = [&] { report(best_chi2); };
  const FitContext cx{lab, dg.base, base_model, base_at, measured, misfit, report_runs};
  for (const Extension& e : menu) {
    dg.fits.push_back(fit_extension(e, cx, base_runs));
    const ExtensionFit& f = dg.fits.back();
    say("diagnose: %-9s %s = %.3g: chi2 %.1f, BIC %.1f (base %.1f), held-out chi2 %.1f (base %.1f)\n",
        e.name.c_str(), e.param.c_str(), free_param(e.param).shown * f.strength, f.best.chi2, f.bic, dg.base_bic,
        f.heldout, dg.base_heldout);
  }
  // A run of an extension fit at strength 0 is a run of the base model: the base fit never ends worse than it.
  if (base_runs.chi2 < dg.base.best.chi2) {
    char note[200];
    std::snprintf(note, sizeof note, "an extension fit's run at strength 0 (the base model) reached chi2 %.1f, below "
                  "the base calibration's %.1f: it is the base fit", base_runs.chi2, dg.base.best.chi2);
    dg.notes.push_back(note);
    say("diagnose: %s\n", note);
    adopt_best(dg.base, base_runs, base);
    surf = response_surfaces(dg.base.design, dg.base.best.u);
    at_best = evaluate_surfaces(surf, dg.base.best.u);
    dg.base_bic = bic(dg.base.best.chi2, d, n);
    dg.base_heldout = heldout_chi2(base_model, d, measured, base_at, lab, misfit);
    fall_back_to_base(dg, d, n);
  }

  if (verbose) progress.finish("");
  dg.generic = fit_generic(dg.base, misfit);
  for (const GenericFit& g : dg.generic)
    say("diagnose: generic   %-12s c = %.3g: chi2 %.1f, BIC %.1f (base %.1f), held-out chi2 %.1f (base %.1f)\n",
        g.shape.name.c_str(), g.c, g.chi2, g.bic, dg.base_bic, g.heldout, dg.base_heldout);
  give_verdict(dg, n, d);
  return dg;
}

}  // namespace dem
