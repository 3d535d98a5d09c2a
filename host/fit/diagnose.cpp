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
  const JointTerm& joint;               ///< the material's other tests, fitted beside the triaxial ones
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
    const std::vector<Real> r = cx.joint.appended(m, cx.misfit.residuals(lab.run_ensemble(m, cx.measured)));
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
    const Model at = model_at(u);
    const Ensemble ens = lab.run_ensemble(at, cx.measured);
    for (const auto& members : ens) ev.sim.push_back(mean_curve(members));
    ev.r = cx.joint.appended(at, cx.misfit.residuals(ens));
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
                   const std::vector<TriaxialTest>& measured, const Misfit& misfit, bool verbose,
                   const JointTerm& joint) {
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
  dg.base = calibrate(lab, base, free0, measured, misfit, 4, [&](long, long, Real chi2) { report(best_chi2 = chi2); },
                      2, joint);
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
  const FitContext cx{lab, dg.base, base_model, base_at, measured, misfit, report_runs, joint};
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
