#include "host/fit/compression_misfit.hpp"

#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "host/fit/misfit.hpp"
#include "host/util/text_format.hpp"

namespace dem {

namespace {

/// The members' mean of each compared value (NaN where no member gives it).
std::vector<Real> mean_values(const std::vector<CompressionTest>& members, bool with_k0) {
  std::vector<Real> sum, n;
  for (const CompressionTest& t : members) {
    const std::vector<Real> v = compression_values(t, with_k0);
    sum.resize(v.size(), 0);
    n.resize(v.size(), 0);
    for (std::size_t i = 0; i < v.size(); ++i)
      if (std::isfinite(v[i])) sum[i] += v[i], n[i] += 1;
  }
  for (std::size_t i = 0; i < sum.size(); ++i) sum[i] = n[i] > 0 ? sum[i] / n[i] : kNaN;
  return sum;
}

}  // namespace

std::vector<Real> compression_values(const CompressionTest& t, bool with_k0) {
  std::vector<Real> v;
  for (std::size_t k = 0; k < t.strain.size(); ++k) v.push_back(t.strain[k] - (k ? t.strain[k - 1] : 0));
  if (with_k0)
    for (std::size_t k = 0; k < t.strain.size(); ++k) v.push_back(k < t.k0.size() ? t.k0[k] : kNaN);
  return v;
}

CompressionMisfit::CompressionMisfit(const std::vector<CompressionTest>& measured, const CompressionEnsemble& scatter,
                                     int members)
    : measured_(measured) {
  if (scatter.size() != measured.size()) throw std::logic_error("compression misfit: a scatter set per test");
  for (std::size_t i = 0; i < measured.size(); ++i) {
    const CompressionTest& t = measured[i];
    const bool with_k0 = !t.k0.empty();
    const std::vector<Real> m = compression_values(t, with_k0);
    std::vector<std::vector<Real>> runs;
    for (const CompressionTest& s : scatter[i]) runs.push_back(compression_values(s, with_k0));
    for (std::size_t j = 0; j < m.size(); ++j) {
      Real sum = 0, sq = 0, S = 0;
      for (const std::vector<Real>& r : runs)
        if (std::isfinite(r[j])) sum += r[j], sq += r[j] * r[j], S += 1;
      if (S < 4)
        throw std::invalid_argument("compression misfit: " + describe(t) + ": " + fmt("%.0f", S) + " of the scatter "
                                    "specimens gave its row " + std::to_string(j % t.strain.size() + 1) +
                                    " (at least 4 needed to measure the simulator's scatter)");
      const Real var = std::max(Real(0), (sq - sum * sum / S) / (S - 1)), nu = S - 1;
      const std::size_t k = j % t.strain.size();
      const bool k0 = j >= t.strain.size();
      Real data_sd = 0;
      if (k0 && !t.k0_sd.empty()) data_sd = t.k0_sd[k];
      if (!k0 && !t.strain_sd.empty())
        data_sd = std::hypot(t.strain_sd[k], k ? t.strain_sd[k - 1] : Real(0));
      const Real sd = std::sqrt(data_sd * data_sd + (1 + Real(1) / members) * var * nu / (nu - 2));
      measured_value_.push_back(m[j]);
      sd_.push_back(std::max(sd, kCompressionFloor * std::fabs(m[j])));
    }
  }
}

std::vector<Real> CompressionMisfit::values(const CompressionEnsemble& sim) const {
  std::vector<Real> v;
  for (std::size_t i = 0; i < measured_.size(); ++i) {
    const std::vector<Real> m = mean_values(sim.at(i), !measured_[i].k0.empty());
    v.insert(v.end(), m.begin(), m.end());
  }
  return v;
}

std::vector<Real> CompressionMisfit::residuals(const CompressionEnsemble& sim) const {
  const std::vector<Real> v = values(sim);
  std::vector<Real> r;
  for (std::size_t j = 0; j < v.size(); ++j)
    r.push_back(std::isfinite(v[j]) ? (v[j] - measured_value_[j]) / sd_[j] : kMissingResidual);
  return r;
}

JointTerm CompressionMisfit::joint(PeriodicLab& lab) const {
  return JointTerm{data(), [this, &lab](const Model& m) { return residuals(lab.run_compressions(m, measured_)); }};
}

std::string CompressionMisfit::table(const CompressionEnsemble& sim) const {
  std::ostringstream s;
  s << "material,test_type,sigma3_kPa,stress_kPa,measured_strain_pct,simulated_strain_pct,measured_K0,simulated_K0\n";
  for (std::size_t i = 0; i < measured_.size(); ++i) {
    const CompressionTest& t = measured_[i];
    const std::vector<Real> m = mean_values(sim.at(i), true);
    Real strain = 0;
    for (std::size_t k = 0; k < t.stress.size(); ++k) {
      strain += m[k];
      s << t.material << "," << path_name(t.path) << "," << fmt("%.6g", t.sigma3 / 1e3) << ","
        << fmt("%.6g", t.stress[k] / 1e3) << "," << fmt("%.6g", 100 * t.strain[k]) << "," << fmt("%.6g", 100 * strain)
        << "," << (t.k0.empty() ? "" : fmt("%.4f", t.k0[k])) << ","
        << (t.path == CompressionPath::oedometer ? fmt("%.4f", m[t.stress.size() + k]) : "") << "\n";
    }
  }
  return s.str();
}

}  // namespace dem
