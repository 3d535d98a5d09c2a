#include "misfit.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <stdexcept>

#include "cell_bias.hpp"
#include "text_format.hpp"

namespace dem {

namespace {
constexpr Real kNaN = std::numeric_limits<Real>::quiet_NaN();
}  // namespace

const char* quantity_name(int q) {
  static const char* names[kQuantities] = {"E_ini", "q_1pct", "q_3pct", "q_peak", "eps_a_peak", "q_end",
                                           "max_dilatancy"};
  return names[q];
}

std::array<Real, kQuantities> quantities(const MeasuredTest& t) {
  return {t.e_ini, t.q_1pct, t.q_3pct, t.q_peak, t.eps_a_peak, t.q_end, t.max_dilatancy};
}

NoiseOptions lab_noise_options(const std::string& path) {
  const LabNoise file = read_lab_noise(path);
  NoiseOptions o;
  o.mode = "lab";
  o.lab = file.curve;
  o.summary = file.summary;
  o.lab_name = "the lab model of " + path;
  return o;
}

Real NoiseModel::sigma(int q, Real measured) const { return std::max(rel[q] * std::fabs(measured), abs[q]); }

bool NoiseModel::is_stress(int q) { return q != kStrainAtPeak && q != kDilatancy; }

namespace {

/// Lab covariance of the summary quantities `idx` of measured values m (NoiseModel).
Eigen::MatrixXd summary_covariance(const std::vector<int>& idx, const std::array<Real, kQuantities>& m,
                                   const NoiseModel& noise) {
  const int n = static_cast<int>(idx.size());
  Eigen::VectorXd shared(n);
  for (int i = 0; i < n; ++i) shared(i) = NoiseModel::is_stress(idx[i]) ? noise.specimen * m[idx[i]] : 0.0;
  Eigen::MatrixXd cov = shared * shared.transpose();
  for (int i = 0; i < n; ++i) {
    const Real total = noise.sigma(idx[i], m[idx[i]]);
    // The shared part cannot exceed the whole scatter; the floor keeps C positive definite when it nearly does.
    cov(i, i) = std::max(total * total, cov(i, i) + 0.01 * total * total);
  }
  return cov;
}

/// r = L^-1 diff over the entries of `present`, L L^T = cov restricted to them; absent entries get
/// kMissingResidual.
std::vector<Real> whiten(const Eigen::MatrixXd& cov, const std::vector<Real>& diff) {
  const int n = static_cast<int>(diff.size());
  std::vector<int> idx;
  for (int i = 0; i < n; ++i)
    if (std::isfinite(diff[i])) idx.push_back(i);
  std::vector<Real> r(n, kMissingResidual);
  const int m = static_cast<int>(idx.size());
  Eigen::MatrixXd c(m, m);
  Eigen::VectorXd d(m);
  for (int a = 0; a < m; ++a) {
    d(a) = diff[idx[a]];
    for (int b = 0; b < m; ++b) c(a, b) = cov(idx[a], idx[b]);
  }
  const Eigen::LLT<Eigen::MatrixXd> llt(c);
  if (llt.info() != Eigen::Success) throw std::logic_error("misfit: noise covariance not positive definite");
  const Eigen::VectorXd w = llt.matrixL().solve(d);
  for (int a = 0; a < m; ++a) r[idx[a]] = w(a);
  return r;
}

}  // namespace

std::array<Real, kQuantities> test_residuals(const MeasuredTest& measured, const MeasuredTest& simulated,
                                             const NoiseModel& noise) {
  const auto m = quantities(measured), s = quantities(simulated);
  std::array<Real, kQuantities> r;
  r.fill(kNaN);
  std::vector<int> idx;
  std::vector<Real> diff;
  for (int q = 0; q < kQuantities; ++q)
    if (std::isfinite(m[q])) idx.push_back(q), diff.push_back(s[q] - m[q]);
  const std::vector<Real> w = whiten(summary_covariance(idx, m, noise), diff);
  for (std::size_t i = 0; i < idx.size(); ++i) r[idx[i]] = w[i];
  return r;
}

// ---------------------------------------------------------------------------------------------------
// The misfit

namespace {

/// The scale that makes a feature comparable across pressures: q in units of sigma3, eps_v as it is.
Real pooled_scale(const Feature& f, Real sigma3) { return f.quantity == 0 ? sigma3 : 1.0; }

/// Correlation along strain of two curve features.
Real strain_correlation(const Feature& a, const Feature& b, Real length) {
  if (a.quantity != b.quantity) return 0;
  return std::exp(-std::fabs(std::log(a.strain / b.strain)) / length);
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
                                const std::vector<MeasuredTest>& measured,
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
      for (const auto& row : v)
        if (std::isfinite(row[f])) p.var[key_of(features[k][f])] += (row[f] - mean[f]) * (row[f] - mean[f]) / (scale * scale);
      p.dof[key_of(features[k][f])] += m - 1;
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
                                 const std::vector<MeasuredTest>& measured) {
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

}  // namespace

std::vector<Real> Misfit::values(std::size_t k, const MeasuredTest& t) const {
  std::vector<Real> out;
  if (!curves_) {
    const auto q = quantities(t);
    for (const Feature& f : features_[k]) out.push_back(q[f.quantity]);
    return out;
  }
  for (const Feature& f : features_[k]) {
    const std::vector<Real>& y = f.quantity == 0 ? t.q : t.eps_v;
    out.push_back(y.empty() || !std::isfinite(t.q_peak) ? kNaN : curve_value(t.eps_a, y, f.strain));
  }
  return out;
}

Misfit::Misfit(const std::vector<MeasuredTest>& measured, const NoiseOptions& noise, const Ensemble& reference,
               int members, Real sim_end, Real sim_balls) {
  if (measured.empty()) throw std::invalid_argument("misfit: no measured tests");
  if (noise.mode != "data" && noise.mode != "lab")
    throw std::invalid_argument("noise '" + noise.mode + "' (allowed: data, lab)");
  if (reference.size() != measured.size()) throw std::logic_error("misfit: the reference ensemble has other tests");
  members_ = std::max(members, 1);
  sim_balls_ = sim_balls;
  for (const auto& runs : reference) {
    Real sum = 0;
    int n = 0;
    for (const MeasuredTest& t : runs)
      if (std::isfinite(t.void_ratio)) sum += t.void_ratio, ++n;
    void_ratio_.push_back(n ? sum / n : kNaN);
  }
  curves_ = !measured.front().q.empty();
  for (const MeasuredTest& t : measured) {
    std::vector<Feature> fs;
    if (!curves_) {
      const auto m = quantities(t);
      for (int q = 0; q < kQuantities; ++q)
        if (std::isfinite(m[q])) fs.push_back({quantity_name(q), q, 0, m[q]});
    } else {
      const Real end = std::min(t.eps_a.back(), 0.999 * sim_end);
      for (int quantity : {0, 1}) {
        if (quantity == 1 && t.eps_v.empty()) continue;
        for (Real e : kFeatureStrains) {
          if (e < t.eps_a.front() || e > end) continue;
          Feature f;
          f.name = std::string(quantity == 0 ? "q" : "eps_v") + " at " + fmt("%g%%", 100 * e);
          f.quantity = quantity;
          f.strain = e;
          f.measured = curve_value(t.eps_a, quantity == 0 ? t.q : t.eps_v, e);
          fs.push_back(f);
        }
      }
    }
    features_.push_back(fs);
  }
  if (curves_)
    build_curve_noise(measured, noise, reference, sim_balls);
  else
    build_summary_noise(measured, noise, reference);
}

int Misfit::data() const {
  int n = 0;
  for (const auto& f : features_) n += static_cast<int>(f.size());
  return n;
}

void Misfit::build_summary_noise(const std::vector<MeasuredTest>& measured, const NoiseOptions& noise,
                                 const Ensemble& ref) {
  const bool given = std::any_of(measured.begin(), measured.end(), [](const MeasuredTest& t) {
    return !t.summary_sd.empty();
  });
  source_ = given && noise.mode == "data" ? "the data's standard-deviation columns" : noise.lab_name;
  for (std::size_t k = 0; k < measured.size(); ++k) {
    std::vector<Feature>& fs = features_[k];
    const int n = static_cast<int>(fs.size());
    std::vector<int> idx;
    for (const Feature& f : fs) idx.push_back(f.quantity);
    Eigen::MatrixXd cov = summary_covariance(idx, quantities(measured[k]), noise.summary);
    for (int i = 0; i < n; ++i) {
      auto sd = measured[k].summary_sd.find(quantity_name(fs[i].quantity));
      if (given && noise.mode == "data") {
        if (sd == measured[k].summary_sd.end()) {
          notes_.push_back(measured[k].material + " at " + fmt("%g kPa: ", 1e-3 * measured[k].sigma3) +
                           quantity_name(fs[i].quantity) + " has no standard deviation: the lab model's is used");
        } else {
          for (int j = 0; j < n; ++j) cov(i, j) = cov(j, i) = 0;
          cov(i, i) = sd->second * sd->second;
        }
      }
      fs[i].data_sd = std::sqrt(cov(i, i));
      // The ensemble's scatter of this quantity (sample variance over the members).
      Real s = 0, s2 = 0;
      int m = 0;
      for (const MeasuredTest& t : ref[k]) {
        const Real v = quantities(t)[fs[i].quantity];
        if (std::isfinite(v)) s += v, s2 += v * v, ++m;
      }
      fs[i].ensemble_sd = m > 1 ? std::sqrt(std::max(Real(0), (s2 - s * s / m) / (m - 1))) : 0;
      cov(i, i) += fs[i].ensemble_sd * fs[i].ensemble_sd / members_;
    }
    cov_.emplace_back(cov.data(), cov.data() + n * n);
  }
}

void Misfit::build_curve_noise(const std::vector<MeasuredTest>& measured, const NoiseOptions& noise,
                               const Ensemble& ref, Real sim_balls) {
  std::vector<std::vector<std::vector<Real>>> z(measured.size());  // [test][member][feature], scaled deviations
  PooledVariance ens, rep = replicate_scatter(features_, measured);
  {
    std::vector<std::vector<std::vector<Real>>> v(measured.size());
    for (std::size_t k = 0; k < measured.size(); ++k)
      for (const MeasuredTest& t : ref[k]) v[k].push_back(values(k, t));
    ens = ensemble_scatter(features_, measured, v, z);
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
    const MeasuredTest& t = measured[k];
    std::vector<Feature>& fs = features_[k];
    const int n = static_cast<int>(fs.size());
    const std::string where = t.material + " at " + fmt("%g kPa", 1e-3 * t.sigma3);
    // The data's own noise of each feature (variance), and whether this test falls back to the lab model.
    bool use_lab = lab;
    std::vector<Real> data_var(n, 0);
    if (!lab) {
      const RowNoise qn = row_noise(t.eps_a, t.q), vn = row_noise(t.eps_a, t.eps_v);
      const bool rows_given = !t.q_sd.empty();
      if (!rows_given && !std::isfinite(qn.sd)) {
        use_lab = rep.var.empty();
        notes_.push_back(where + ": " + std::to_string(t.q.size()) + " rows, fewer than " +
                         std::to_string(kMinNoiseRows) + " to estimate noise from: " +
                         (use_lab ? "the lab model is used" : "replicates alone give it"));
      } else if (rows_given) {
        notes_.push_back(where + ": noise from the standard-deviation columns");
      } else {
        notes_.push_back(where + ": noise estimated from the rows' scatter: q " + fmt("%.3g kPa", 1e-3 * qn.sd) +
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
    }
    Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(n, n);
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
      }
      f.data_sd = std::sqrt(data_var[i]);
    }
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        const Feature &a = fs[i], &b = fs[j];
        const Real rho = i == j ? 1 : strain_correlation(a, b, use_lab ? noise.lab.length : length_);
        Real c = rho * (a.specimen_sd * b.specimen_sd + a.ensemble_sd * b.ensemble_sd / members_);
        if (use_lab && a.quantity == 0 && b.quantity == 0) {
          // The lab's specimen factor moves the whole q curve together: rank one, beside the correlated rest.
          const Real sh = noise.lab.q_shared;
          const Real rest = rho * (a.specimen_sd * b.specimen_sd - sh * sh * std::fabs(a.measured * b.measured));
          c = sh * sh * a.measured * b.measured + std::max(Real(0), rest) +
              rho * a.ensemble_sd * b.ensemble_sd / members_;
        }
        cov(i, j) = c;
      }
    for (int i = 0; i < n; ++i) {
      cov(i, i) += data_var[i];
      // A floor of 1e-3 of the feature's own scale keeps Sigma invertible where every part is zero (a curve and an
      // ensemble without noise): 0.1% of sigma3 on q, 1e-6 on eps_v.
      const Real floor = fs[i].quantity == 0 ? 1e-3 * t.sigma3 : 1e-6;
      cov(i, i) += floor * floor;
    }
    cov_.emplace_back(cov.data(), cov.data() + n * n);
  }
  if (lab)
    notes_.push_back("noise: " + noise.lab_name + fmt(" (q %.3g%%", 100 * noise.lab.q_rel) +
                     fmt(" with a %.3g%% specimen factor", 100 * noise.lab.q_shared) +
                     fmt(", eps_v %.3g%%", 100 * noise.lab.ev_rel) + fmt(" or %.3g%%)", 100 * noise.lab.ev_abs));
}

void Misfit::add_cell_bias(const std::vector<std::vector<Real>>& sd, const std::string& note) {
  if (sd.size() != features_.size()) throw std::logic_error("misfit: a cell bias for other tests");
  for (std::size_t k = 0; k < features_.size(); ++k) {
    std::vector<Feature>& fs = features_[k];
    const int n = static_cast<int>(fs.size());
    if (static_cast<int>(sd[k].size()) != n) throw std::logic_error("misfit: a cell bias for other data");
    for (int i = 0; i < n; ++i) fs[i].cell_sd = sd[k][i];
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        // Summary quantities are all of one strain (0): a bias of one is taken as independent of the others'.
        const Real rho = i == j ? 1 : curves_ ? strain_correlation(fs[i], fs[j], length_) : 0;
        cov_[k][static_cast<std::size_t>(i) * n + j] += rho * fs[i].cell_sd * fs[j].cell_sd;
      }
  }
  notes_.push_back(note);
}

Real Misfit::ensemble_ratio() const {
  std::vector<Real> r;
  for (const auto& fs : features_)
    for (const Feature& f : fs) {
      const Real data = f.data_noise();
      if (data > 0) r.push_back(f.ensemble_sd / std::sqrt(static_cast<Real>(members_)) / data);
    }
  if (r.empty()) return 0;
  std::nth_element(r.begin(), r.begin() + r.size() / 2, r.end());
  return r[r.size() / 2];
}

int Misfit::members_for(Real target) const {
  const Real r = ensemble_ratio() / target;
  return std::max(1, static_cast<int>(std::ceil(members_ * r * r - 1e-9)));
}

Misfit measure_misfit(PeriodicLab& lab, const Model& base, const std::vector<MeasuredTest>& measured,
                      const NoiseOptions& noise, bool cell_bias) {
  Ensemble scatter = lab.run_ensemble(base, measured, true);
  auto misfit = [&] {
    return Misfit(measured, noise, scatter, lab.members(), lab.config().periodic.triax.target_strain,
                  static_cast<Real>(lab.balls()));
  };
  if (lab.config().calibrate.ensemble == kAutoEnsemble) {
    lab.set_members(lab.specimens());
    const int wanted = misfit().members_for(kEnsembleRatioGoal);
    // The cap is on the cell, not on one step: a lab shared by several materials may have grown for an earlier one.
    const int room = kMaxCellFactor / lab.cell_factor();
    if (wanted > lab.specimens() && room > 1 && lab.config().calibrate.cell_factor == kAutoCell) {
      lab.grow_cell(std::min(room, (wanted + lab.specimens() - 1) / lab.specimens()));
      scatter = lab.run_ensemble(base, measured, true);
    }
    lab.set_members(std::min(misfit().members_for(kEnsembleRatioGoal), lab.specimens()));
  }
  Misfit m = misfit();
  if (cell_bias) measure_cell_bias(lab, base, measured, scatter, m);
  return m;
}

std::vector<Real> Misfit::mean_values(std::size_t k, const std::vector<MeasuredTest>& members) const {
  std::vector<Real> sum(features_[k].size(), 0.0);
  std::vector<int> n(sum.size(), 0);
  for (const MeasuredTest& t : members) {
    const std::vector<Real> v = values(k, t);
    for (std::size_t f = 0; f < v.size(); ++f)
      if (std::isfinite(v[f])) sum[f] += v[f], ++n[f];
  }
  for (std::size_t f = 0; f < sum.size(); ++f) sum[f] = n[f] ? sum[f] / n[f] : kNaN;
  return sum;
}

std::vector<Real> Misfit::test_residuals(std::size_t k, const std::vector<MeasuredTest>& members) const {
  const std::vector<Real> s = mean_values(k, members);
  const int n = static_cast<int>(s.size());
  std::vector<Real> diff(n);
  for (int i = 0; i < n; ++i) diff[i] = s[i] - features_[k][i].measured;
  const Eigen::Map<const Eigen::MatrixXd> cov(cov_[k].data(), n, n);
  return whiten(cov, diff);
}

std::vector<Real> Misfit::residuals(const Ensemble& sim) const {
  std::vector<Real> r;
  for (std::size_t k = 0; k < features_.size(); ++k) {
    const std::vector<Real> t = test_residuals(k, sim[k]);
    r.insert(r.end(), t.begin(), t.end());
  }
  return r;
}

}  // namespace dem
