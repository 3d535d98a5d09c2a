#include "host/fit/calibrate.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

// What a search runs and counts (host/fit/calibrate.hpp): the significant gain, the screening's bound and rule, and the
// periodic lab's simulator, which runs a point on one member first and screens it.

namespace dem {

namespace {

/// The joint 95% region's rise at a best chi2, as add_uncertainty counts it.
Real region_rise_at(Real best_chi2, int data, int d) {
  return chi2_95(std::max(d, 1)) * std::max(Real(1), best_chi2 / std::max(1, data - d));
}

}  // namespace

Real significant_gain(Real best_chi2, int data, int d) { return 0.05 * region_rise_at(best_chi2, data, d); }

Real screen_bound(Real best_chi2, int data, int d) { return best_chi2 + region_rise_at(best_chi2, data, d); }

bool clearly_above(const std::vector<Real>& r, Real spread, Real bound) {
  return std::sqrt(sum_sq(r)) - kScreenSigmas * std::sqrt(std::max(Real(0), spread)) > std::sqrt(bound);
}

CalibrationResult calibrate(PeriodicLab& lab, const Model& base, const std::vector<FreeParam>& free,
                            const std::vector<TriaxialTest>& measured, const Misfit& misfit, int rounds,
                            const CalibrationProgress& progress, int widen, const JointTerm& joint) {
  const long planned = planned_points(static_cast<int>(free.size()), rounds) * static_cast<long>(measured.size()) *
                       lab.members();
  Real best = std::numeric_limits<Real>::infinity();
  const Real spread = misfit.member_spread();
  // The first parts that probes ran, each taken up by its point's next call.
  std::vector<std::pair<Model, Ensemble>> probed;
  // The joint tests' residuals of each model, run once: a probe's point is called twice.
  std::vector<std::pair<Model, std::vector<Real>>> joint_done;
  JointTerm once = joint;
  if (joint.residuals) once.residuals = [&](const Model& m) {
    auto was = std::find_if(joint_done.begin(), joint_done.end(), [&](const auto& p) { return same_model(p.first, m); });
    if (was == joint_done.end()) was = joint_done.insert(joint_done.end(), {m, joint.residuals(m)});
    return was->second;
  };
  auto simulate = [&](const Model& m, Real screen_above) {
    SimulatedPoint s;
    const std::size_t K = static_cast<std::size_t>(lab.members()), T = measured.size(),
                      W = static_cast<std::size_t>(std::max(1, lab.workers()));
    // The first member's tests, and as many of the next member's as fill the workers' last round: a point that is
    // not screened then takes the rounds of the whole ensemble at once.
    const std::size_t first = std::min(T * K, (T + W - 1) / W * W);
    const bool parts = K > 1 && first < T * K && (screen_above == kProbe || std::isfinite(screen_above));
    const auto was = std::find_if(probed.begin(), probed.end(), [&](const auto& p) { return same_model(p.first, m); });
    Ensemble ens;
    if (was != probed.end()) {
      ens = std::move(was->second);
      probed.erase(was);
    } else {
      ens = lab.run_part(m, measured, K, 0, parts ? first : T * K);
    }
    if (ens.back().size() < K) {  // the first part: the last test has its first member only
      Ensemble one(T);
      for (std::size_t k = 0; k < T; ++k) one[k].push_back(ens[k].front());
      s.r = once.appended(m, misfit.residuals(one));
      s.screened = screen_above == kProbe || clearly_above(s.r, spread, screen_above);
      if (s.screened) {
        if (screen_above == kProbe) probed.emplace_back(m, ens);
        ens = one;
      } else {
        const Ensemble rest = lab.run_part(m, measured, K, first, T * K);
        for (std::size_t k = 0; k < T; ++k) ens[k].insert(ens[k].end(), rest[k].begin(), rest[k].end());
      }
    }
    for (const auto& one : ens) s.sim.push_back(mean_curve(one));
    s.r = once.appended(m, misfit.residuals(ens));
    if (!s.screened) best = std::min(best, sum_sq(s.r));
    if (progress) progress(lab.runs(), planned, best);
    return s;
  };
  return calibrate(simulate, base, free, misfit.data() + joint.data, rounds, widen);
}

CalibrationResult calibrate_one_specimen(PeriodicLab& lab, const Model& base, const std::vector<FreeParam>& free,
                                         const std::vector<TriaxialTest>& measured, const Misfit& misfit,
                                         const CalibrationProgress& progress, int widen) {
  const std::size_t T = measured.size(), S = static_cast<std::size_t>(lab.specimens());
  OneSpecimenSearch one;
  const Ensemble& scatter = misfit.budget().scatter;
  for (std::size_t s = 0; s < S && !scatter.empty() && s < scatter.front().size(); ++s) {
    Ensemble run(T);
    for (std::size_t k = 0; k < T; ++k) run[k].push_back(scatter[k][s]);
    SimulatedPoint p;
    for (const auto& member : run) p.sim.push_back(member.front());
    p.r = misfit.residuals(run);
    p.specimen = static_cast<int>(s);
    one.at_base.push_back(std::move(p));
  }
  const long planned = planned_one_specimen_points(static_cast<int>(free.size())) * static_cast<long>(T);
  Real best = std::numeric_limits<Real>::infinity();
  std::size_t next = one.at_base.size() % S;  // the turn goes on after the scatter runs' specimens
  auto simulate = [&](const Model& m, Real) {
    const std::size_t s = next;
    next = (next + 1) % S;
    const Ensemble run = lab.run_part(m, measured, S, s * T, (s + 1) * T);
    SimulatedPoint p;
    for (const auto& member : run) p.sim.push_back(member.front());
    p.r = misfit.residuals(run);
    p.specimen = static_cast<int>(s);
    best = std::min(best, sum_sq(p.r));
    if (progress) progress(lab.runs(), planned, best);
    return p;
  };
  return calibrate(simulate, base, free, misfit.data(), one, widen);
}

}  // namespace dem
