#include "host/fit/misfit.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

#include "host/util/text_format.hpp"

/// Sigma of curve data (misfit.hpp): the data's own noise, the specimen's, the simulator's ensemble scatter and its
/// cell's bias, each correlated along strain.

namespace dem {

namespace {

/// The scale that makes a feature comparable across pressures: q in units of sigma3, eps_v as it is.
Real pooled_scale(const Feature& f, Real sigma3) { return f.quantity == 0 ? sigma3 : 1.0; }

/// Calls f(i, j, rho) for every ordered pair of the features `fs` (n x n), rho their correlation: 1 on the
/// diagonal, exp(-|ln e_i - ln e_j| / length) between curve features of one quantity, 0 otherwise. Summary
/// quantities (`along_strain` false) are all of one strain: each is taken as independent of the others.
template <class F>
void for_each_pair(const std::vector<Feature>& fs, Real length, bool along_strain, F&& f) {
  const int n = static_cast<int>(fs.size());
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const Feature &a = fs[i], &b = fs[j];
      const bool related = along_strain && a.quantity == b.quantity;
      f(i, j, i == j ? 1 : related ? std::exp(-std::fabs(std::log(a.strain / b.strain)) / length) : Real(0));
    }
}

/// Key of a curve feature across tests: (quantity, strain).
using FeatureKey = std::pair<int, Real>;
FeatureKey key_of(const Feature& f) { return {f.quantity, f.strain}; }

/// A variance per feature key, pooled over tests (q in units of sigma3), with its degrees of freedom.
struct PooledVariance {
  std::map<FeatureKey, Real> var;
  std::map<FeatureKey, int> dof;
};

/// The simulator's scatter: member deviations from their test's mean (`values` [test][member][feature]),
/// pooled over tests per feature key and inflated by Student's t; `z` receives the scaled deviations.
PooledVariance ensemble_scatter(const std::vector<std::vector<Feature>>& features,
                                const std::vector<TriaxialTest>& measured,
                                const std::vector<std::vector<std::vector<Real>>>& values,
                                std::vector<std::vector<std::vector<Real>>>& z) {
  PooledVariance p;
  for (std::size_t k = 0; k < measured.size(); ++k) {
    const std::vector<std::vector<Real>>& v = values[k];
    const std::size_t nf = features[k].size();
    std::vector<Real> mean(nf);
    for (std::size_t f = 0; f < nf; ++f) {
      Real s = 0;
      int m = 0;
      for (const auto& row : v)
        if (std::isfinite(row[f])) s += row[f], ++m;
      mean[f] = s / std::max(m, 1);
      if (m < 2) continue;
      const Real scale = pooled_scale(features[k][f], measured[k].sigma3);
      const FeatureKey key = key_of(features[k][f]);
      for (const auto& row : v)
        if (std::isfinite(row[f])) p.var[key] += (row[f] - mean[f]) * (row[f] - mean[f]) / (scale * scale);
      p.dof[key] += m - 1;
    }
    for (const auto& row : v) {
      std::vector<Real> d(nf);
      for (std::size_t f = 0; f < nf; ++f) d[f] = (row[f] - mean[f]) / pooled_scale(features[k][f], measured[k].sigma3);
      z[k].push_back(d);
    }
  }
  // Student's t: the variance of a deviation measured against an estimate of nu degrees of freedom.
  const Real nu = static_cast<Real>(values.front().size()) - 1;
  const Real t_factor = nu > 2 ? nu / (nu - 2) : 3;
  for (auto& [key, var] : p.var) var = t_factor * var / std::max(p.dof[key], 1);
  return p;
}

/// The correlation length along strain: ln rho = -|d ln e| / l fitted through the origin to the pooled sample
/// correlations of the deviations z of pairs of one quantity (clamped to [0.3, 5]: from one strain decade of
/// independence to near-rigid offsets); `fallback` when no pair is usable.
Real fitted_length(const std::vector<std::vector<Feature>>& features,
                   const std::vector<std::vector<std::vector<Real>>>& z, Real fallback) {
  Real num = 0, den = 0;
  const std::vector<Feature>& fs0 = features.front();
  for (std::size_t a = 0; a < fs0.size(); ++a)
    for (std::size_t b = a + 1; b < fs0.size(); ++b) {
      if (fs0[a].quantity != fs0[b].quantity) continue;
      Real sab = 0, saa = 0, sbb = 0;
      for (std::size_t k = 0; k < features.size(); ++k) {
        if (features[k].size() != fs0.size()) continue;
        for (const auto& d : z[k])
          if (std::isfinite(d[a]) && std::isfinite(d[b])) sab += d[a] * d[b], saa += d[a] * d[a], sbb += d[b] * d[b];
      }
      const Real r = saa > 0 && sbb > 0 ? sab / std::sqrt(saa * sbb) : 0;
      if (r <= 0.05 || r >= 0.999) continue;
      const Real dl = std::fabs(std::log(fs0[a].strain / fs0[b].strain));
      num += dl * dl, den += -dl * std::log(r);
    }
  return den > 0 ? std::clamp(num / den, Real(0.3), Real(5)) : fallback;
}

/// Replicates: the pooled scatter between the tests of one material and pressure holds data and specimen noise.
PooledVariance replicate_scatter(const std::vector<std::vector<Feature>>& features,
                                 const std::vector<TriaxialTest>& measured) {
  PooledVariance p;
  for (const auto& g : replicate_groups(measured)) {
    if (g.size() < 2) continue;
    std::map<FeatureKey, std::vector<Real>> vals;
    for (std::size_t k : g)
      for (const Feature& f : features[k]) vals[key_of(f)].push_back(f.measured / pooled_scale(f, measured[k].sigma3));
    for (const auto& [key, v] : vals) {
      if (v.size() < 2) continue;
      Real s = 0;
      for (Real x : v) s += x;
      for (Real x : v) p.var[key] += (x - s / v.size()) * (x - s / v.size());
      p.dof[key] += static_cast<int>(v.size()) - 1;
    }
  }
  for (auto& [key, var] : p.var) var /= p.dof[key];
  return p;
}

/// A test's own noise of each feature (variances, in `data_var`), from its standard-deviation columns or the scatter
/// of its rows; false where it has too few rows for either and no replicates: the lab model is used instead.
/// `notes` gets what was done, `where` naming the test.
bool data_noise(const TriaxialTest& t, const std::vector<Feature>& fs, bool have_replicates, const std::string& where,
                std::vector<Real>& data_var, std::vector<std::string>& notes) {
  const int n = static_cast<int>(fs.size());
  bool use_lab = false;
  const RowNoise qn = row_noise(t.eps_a, t.q), vn = row_noise(t.eps_a, t.eps_v);
  const bool rows_given = !t.q_sd.empty();
  if (!rows_given && !std::isfinite(qn.sd)) {
    use_lab = !have_replicates;
    notes.push_back(where + ": " + std::to_string(t.q.size()) + " rows, fewer than " +
                    std::to_string(kMinNoiseRows) + " to estimate noise from: " +
                    (use_lab ? "the lab model is used" : "replicates alone give it"));
  } else if (rows_given) {
    notes.push_back(where + ": noise from the standard-deviation columns");
  } else {
    notes.push_back(where + ": noise estimated from the rows' scatter: q " + fmt("%.3g kPa", 1e-3 * qn.sd) +
                    fmt(" (lag-1 correlation %.2f)", qn.rho) +
                    (t.eps_v.empty() ? std::string() : ", eps_v " + fmt("%.3g%%", 100 * vn.sd) +
                                                           fmt(" (%.2f)", vn.rho)));
  }
  for (int i = 0; i < n && !use_lab; ++i) {
    const Feature& f = fs[i];
    const std::vector<Real>& sdv = f.quantity == 0 ? t.q_sd : t.eps_v_sd;
    const Real h = feature_window(f.strain);
    const auto rows = std::upper_bound(t.eps_a.begin(), t.eps_a.end(), f.strain + h) -
                      std::lower_bound(t.eps_a.begin(), t.eps_a.end(), f.strain - h);
    const Real nw = std::max<Real>(1, static_cast<Real>(rows));
    if (!sdv.empty()) {
      const Real sd = curve_value(t.eps_a, sdv, f.strain);
      data_var[i] = sd * sd / nw;  // rows given with their own errors: independent
    } else if (std::isfinite(qn.sd)) {
      const RowNoise& rn = f.quantity == 0 ? qn : vn;
      data_var[i] = rn.sd * rn.sd * std::min<Real>(1, (1 + rn.rho) / ((1 - rn.rho) * nw));
    }
  }
  return !use_lab;
}

}  // namespace

void Misfit::build_curve_noise(const std::vector<TriaxialTest>& measured, const NoiseOptions& noise,
                               const Ensemble& ref, Real sim_balls, const Ensemble& floor) {
  std::vector<std::vector<std::vector<Real>>> z(measured.size());  // [test][member][feature], scaled deviations
  PooledVariance ens, rep = replicate_scatter(features_, measured);
  auto pooled = [&](const Ensemble& runs, std::vector<std::vector<std::vector<Real>>>& deviations) {
    std::vector<std::vector<std::vector<Real>>> v(measured.size());
    for (std::size_t k = 0; k < measured.size(); ++k)
      for (const TriaxialTest& t : runs[k]) v[k].push_back(values(k, t));
    return ensemble_scatter(features_, measured, v, deviations);
  };
  ens = pooled(ref, z);
  if (!floor.empty()) {  // each feature's variance at least the floor's (its correlation length stays ref's)
    std::vector<std::vector<std::vector<Real>>> unused(measured.size());
    const PooledVariance low = pooled(floor, unused);
    for (auto& [key, var] : ens.var)
      if (const auto f = low.var.find(key); f != low.var.end()) var = std::max(var, f->second);
  }
  length_ = ref.front().size() > 2 ? fitted_length(features_, z, noise.lab.length) : noise.lab.length;
  const bool lab = noise.mode == "lab";
  const bool no_ensemble = ens.var.empty();
  source_ = lab ? noise.lab_name : !rep.var.empty() ? "replicates" : "the data";
  if (!lab && !rep.var.empty())
    notes_.push_back("replicates: the scatter between tests of one material and pressure (pooled over " +
                     std::to_string(rep.dof.begin()->second) + " degrees of freedom) is the data and specimen noise");
  if (no_ensemble)
    notes_.push_back("the simulator has one specimen: its scatter is not measured and counts as zero");

  for (std::size_t k = 0; k < measured.size(); ++k) {
    const TriaxialTest& t = measured[k];
    std::vector<Feature>& fs = features_[k];
    const int n = static_cast<int>(fs.size());
    const std::string where = t.material + " at " + fmt("%g kPa", 1e-3 * t.sigma3);
    // The data's own noise of each feature (variance), and whether this test falls back to the lab model.
    std::vector<Real> data_var(n, 0);
    const bool use_lab = lab || !data_noise(t, fs, !rep.var.empty(), where, data_var, notes_);
    std::vector<char> sim_specimen(n, 0);  // the specimen term is the simulator's scatter, scaled
    for (int i = 0; i < n; ++i) {
      Feature& f = fs[i];
      const Real scale = pooled_scale(f, t.sigma3);
      auto e = ens.var.find(key_of(f));
      f.ensemble_sd = e == ens.var.end() ? 0 : std::sqrt(e->second) * scale;
      auto r = rep.var.find(key_of(f));
      const bool from_rep = !use_lab && !lab && r != rep.var.end();
      if (use_lab) {
        const Real lab_sd = f.quantity == 0 ? std::max(noise.lab.q_rel * std::fabs(f.measured), 2e-3 * t.sigma3)
                                            : std::max(noise.lab.ev_rel * std::fabs(f.measured), noise.lab.ev_abs);
        f.specimen_sd = lab_sd;
      } else if (from_rep) {
        f.specimen_sd = std::sqrt(r->second) * scale;
        data_var[i] = 0;  // the replicates' scatter holds it
      } else {
        const bool sized = std::isfinite(t.specimen_balls) && sim_balls > 0;
        const Real floor = f.quantity == 0 ? noise.lab.q_shared * std::fabs(f.measured) : noise.lab.ev_abs;
        const Real size = sized ? std::pow(sim_balls / t.specimen_balls, kSpecimenScatterExponent) : 1;
        f.specimen_sd = std::max(f.ensemble_sd * size, floor);
        sim_specimen[i] = 1;
      }
      f.data_sd = std::sqrt(data_var[i]);
    }
    add_test_covariance(fs, use_lab ? noise.lab.length : length_, use_lab ? &noise.lab : nullptr, sim_specimen,
                        data_var, t.sigma3);
  }
  if (lab)
    notes_.push_back("noise: " + noise.lab_name + fmt(" (q %.3g%%", 100 * noise.lab.q_rel) +
                     fmt(" with a %.3g%% specimen factor", 100 * noise.lab.q_shared) +
                     fmt(", eps_v %.3g%%", 100 * noise.lab.ev_rel) + fmt(" or %.3g%%)", 100 * noise.lab.ev_abs));
}

void Misfit::add_test_covariance(const std::vector<Feature>& fs, Real length, const LabCurveNoise* lab,
                                 const std::vector<char>& sim_specimen, const std::vector<Real>& data_var,
                                 Real sigma3) {
  const int n = static_cast<int>(fs.size());
  Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(n, n);
  std::vector<Real> member(static_cast<std::size_t>(n) * n), spread(member.size());
  for_each_pair(fs, length, true, [&](int i, int j, Real rho) {
    const Feature &a = fs[i], &b = fs[j];
    member[static_cast<std::size_t>(i) * n + j] = rho * a.ensemble_sd * b.ensemble_sd;
    spread[static_cast<std::size_t>(i) * n + j] =
        rho * ((sim_specimen[i] && sim_specimen[j] ? a.specimen_sd * b.specimen_sd : 0) +
               a.ensemble_sd * b.ensemble_sd / members_);
    Real c = rho * (a.specimen_sd * b.specimen_sd + a.ensemble_sd * b.ensemble_sd / members_);
    if (lab && a.quantity == 0 && b.quantity == 0) {
      // The lab's specimen factor moves the whole q curve together: rank one, beside the correlated rest.
      const Real sh = lab->q_shared;
      const Real rest = rho * (a.specimen_sd * b.specimen_sd - sh * sh * std::fabs(a.measured * b.measured));
      c = sh * sh * a.measured * b.measured + std::max(Real(0), rest) +
          rho * a.ensemble_sd * b.ensemble_sd / members_;
    }
    cov(i, j) = c;
  });
  for (int i = 0; i < n; ++i) {
    cov(i, i) += data_var[i];
    // A floor of 1e-3 of the feature's own scale keeps Sigma invertible where every part is zero (a curve and an
    // ensemble without noise): 0.1% of sigma3 on q, 1e-6 on eps_v.
    const Real floor = fs[i].quantity == 0 ? 1e-3 * sigma3 : 1e-6;
    cov(i, i) += floor * floor;
  }
  cov_.emplace_back(cov.data(), cov.data() + n * n);
  member_cov_.push_back(member);
  spread_cov_.push_back(spread);
}

void Misfit::add_correlated(const std::vector<std::vector<Real>>& sd, Real Feature::*field, const std::string& what) {
  if (sd.size() != features_.size()) throw std::logic_error("misfit: a " + what + " for other tests");
  for (std::size_t k = 0; k < features_.size(); ++k) {
    std::vector<Feature>& fs = features_[k];
    const int n = static_cast<int>(fs.size());
    if (static_cast<int>(sd[k].size()) != n) throw std::logic_error("misfit: a " + what + " for other data");
    for (int i = 0; i < n; ++i) fs[i].*field = sd[k][i];
    for_each_pair(fs, length_, curves_, [&](int i, int j, Real rho) {
      cov_[k][static_cast<std::size_t>(i) * n + j] += rho * fs[i].*field * fs[j].*field;
    });
  }
}

void Misfit::add_cell_bias(const CellBias& bias) {
  add_correlated(bias.sd, &Feature::cell_sd, "cell bias");
  notes_.push_back(bias.note);
  cell_finding_ = bias.finding;
}

void Misfit::add_discrepancy(const std::vector<std::vector<Real>>& delta, const std::vector<std::vector<Real>>& sd,
                             const std::string& note) {
  if (delta.size() != features_.size()) throw std::logic_error("misfit: a discrepancy for other tests");
  for (std::size_t k = 0; k < features_.size(); ++k)
    if (delta[k].size() != features_[k].size()) throw std::logic_error("misfit: a discrepancy for other data");
  add_correlated(sd, &Feature::discrepancy_sd, "discrepancy");
  from_budget_ = false;  // with_scatter would rebuild it without the discrepancy
  for (std::size_t k = 0; k < features_.size(); ++k)
    for (std::size_t i = 0; i < delta[k].size(); ++i) features_[k][i].measured -= delta[k][i];
  notes_.push_back(note);
}

}  // namespace dem
