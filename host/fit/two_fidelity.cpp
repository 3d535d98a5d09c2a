#include "host/fit/two_fidelity.hpp"

#include <cmath>
#include <stdexcept>

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

bool scales_with_stress(const Feature& f) {
  if (f.strain > 0) return f.quantity == 0;  // a curve's q (eps_v is quantity 1)
  return f.quantity != kStrainAtPeak && f.quantity != kDilatancy;
}

Discrepancy measure_discrepancy(const Misfit& misfit, const std::vector<Prediction>& membrane,
                                const Ensemble& periodic) {
  if (membrane.size() != misfit.tests() || periodic.size() != misfit.tests())
    throw std::logic_error("two-fidelity: runs for other tests than the misfit's");
  Discrepancy d;
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

}  // namespace dem
