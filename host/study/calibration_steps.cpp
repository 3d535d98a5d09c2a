/// A calibration's steps after its search (calibration_session.hpp): the simulator's scatter measured again at the
/// answer, and the reference point placed against the joint region.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "host/fit/calibration_report.hpp"
#include "host/study/calibration_session.hpp"
#include "host/util/progress.hpp"
#include "host/util/text_format.hpp"

namespace dem {

Misfit rescattered(Session& ss, const std::string& material, const std::vector<TriaxialTest>& tests,
                   const Misfit& misfit, CalibrationResult& r, const Model& base) {
  const long start = ss.lab.runs();
  Progress progress("calibrate " + material + ": the scatter at the calibrated point",
                    static_cast<long>(tests.size()) * ss.lab.specimens());
  const Ensemble scatter = ss.lab.run_ensemble(r.model, tests, true);
  progress.finish(std::to_string(ss.lab.runs() - start) + " runs");
  int members = 0;  // the ensemble's, as the budget decided
  if (r.surrogate_answer) {
    // One specimen a point: the scatter runs are design points at the answer too, its curves their mean, and the
    // simulator's mean there counts as the ensemble the surfaces are worth (the fewer specimens, the more scatter).
    Evaluation at = r.best;
    at.sim.clear();
    for (const std::vector<TriaxialTest>& runs : scatter) at.sim.push_back(mean_curve(runs));
    for (std::size_t s = 0; s < scatter.front().size(); ++s) {
      Evaluation e = r.best;
      e.sim.clear();
      for (const std::vector<TriaxialTest>& runs : scatter) e.sim.push_back(runs[s]);
      e.specimen = static_cast<int>(s);
      r.design.push_back(std::move(e));
    }
    r.best = at;
    members = std::max(1, static_cast<int>(r.surrogate_members()));
    std::printf("calibrate: %s: one specimen a point: the surfaces at the answer are worth the mean of %d specimens "
                "(%.1f)\n", material.c_str(), members, r.surrogate_members());
  }
  const Misfit there = misfit.with_scatter(scatter, members);
  std::vector<Real> ratio;
  for (std::size_t k = 0; k < tests.size(); ++k)
    for (std::size_t i = 0; i < there.features(k).size(); ++i)
      if (misfit.features(k)[i].ensemble_sd > 0) ratio.push_back(there.features(k)[i].ensemble_sd /
                                                                 misfit.features(k)[i].ensemble_sd);
  std::sort(ratio.begin(), ratio.end());
  const Real before = r.best.chi2;
  rewhiten(r, there, base);
  std::printf("calibrate: %s: the simulator's scatter measured at the calibrated point too, each datum's the larger of "
              "the two: %s of the base model's (median over the data; %s to %s); the design whitened by it: best chi2 "
              "%.1f (was %.1f)\n", material.c_str(),
              ratio.empty() ? "-" : fmt("%.2f", ratio[ratio.size() / 2]).c_str(),
              ratio.empty() ? "-" : fmt("%.2f", ratio.front()).c_str(),
              ratio.empty() ? "-" : fmt("%.2f", ratio.back()).c_str(), r.best.chi2, before);
  return there;
}

std::pair<Real, Real> place_reference(Session& ss, const std::string& material, const std::vector<TriaxialTest>& tests,
                                      const Misfit& misfit, const CalibrationResult& r) {
  const std::vector<Real> reference = ss.in.reference_point(material);
  Real rise = std::nan(""), chi2 = std::nan("");
  if (!std::all_of(reference.begin(), reference.end(), [](Real v) { return std::isfinite(v); })) return {rise, chi2};
  Model at = r.model;
  std::vector<Real> si;
  for (std::size_t k = 0; k < ss.in.free.size(); ++k) {
    si.push_back(reference[k] / ss.in.free[k].shown);
    set_param(at, ss.in.free[k].name, si.back());
  }
  rise = r.region_rise(si);
  if (ss.in.runs_reference(material)) {
    const long start = ss.lab.runs();
    Progress progress("calibrate " + material + ": the reference point", static_cast<long>(tests.size()) *
                      ss.lab.members());
    chi2 = sum_sq(misfit.residuals(ss.lab.run_ensemble(at, tests)));
    progress.finish(std::to_string(ss.lab.runs() - start) + " runs");
  }
  std::printf("%s", reference_text(r, reference, chi2, material, "calibrate").c_str());
  return {rise, chi2};
}

}  // namespace dem
