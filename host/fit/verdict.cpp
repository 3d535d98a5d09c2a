/// The diagnosis's verdict (host/fit/diagnose.hpp, give_verdict): each extension weighed on BIC and the held-out chi2
/// against the base model and the generic rival, and the verdict with its explanation in words.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "host/fit/diagnose.hpp"
#include "host/util/text_format.hpp"

namespace dem {

namespace {

/// A BIC difference between two specific extensions below 2 is not worth more than a bare mention: a tie.
constexpr Real kTieBIC = 2;

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

}  // namespace dem
