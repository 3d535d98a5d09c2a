#include "host/fit/misfit.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "host/util/text_format.hpp"

namespace dem {

std::array<Real, kQuantities> quantities(const TriaxialTest& t) {
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

std::pair<double, const char*> in_table_unit(int q, Real v) {
  if (q == kInitialStiffness) return {1e-6 * v, "MPa"};
  if (q == kStrainAtPeak) return {100 * v, "pct"};
  if (q == kDilatancy) return {v, "-"};
  return {1e-3 * v, "kPa"};
}

std::pair<double, const char*> feature_unit(const Feature& f, Real v) {
  if (f.strain == 0) return in_table_unit(f.quantity, v);
  return f.quantity == 0 ? std::make_pair(1e-3 * v, "kPa") : std::make_pair(100 * v, "pct");
}

std::string quantity_group(const Feature& f) {
  if (f.strain > 0) return f.quantity == 0 ? "q" : "eps_v";
  return f.name;
}

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

std::array<Real, kQuantities> test_residuals(const TriaxialTest& measured, const TriaxialTest& simulated,
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

std::vector<Real> Misfit::values(std::size_t k, const TriaxialTest& t) const {
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

Misfit::Misfit(const std::vector<TriaxialTest>& measured, const NoiseOptions& noise, const NoiseBudget& budget)
    : Misfit(measured, noise, budget.scatter, budget.members, budget.sim_end, budget.sim_balls, budget.scatter_floor) {
  if (!budget.cell_bias.sd.empty()) add_cell_bias(budget.cell_bias);
  measured_ = measured;
  noise_ = noise;
  budget_ = budget;
  from_budget_ = true;
}

Misfit Misfit::with_scatter(const Ensemble& scatter, int members) const {
  if (!from_budget_) throw std::logic_error("misfit: with_scatter needs a misfit of a noise budget, without a discrepancy");
  NoiseBudget b = budget_;
  if (b.scatter_floor.empty()) b.scatter_floor = b.scatter;
  b.scatter = scatter;
  if (members > 0) b.members = members;
  return Misfit(measured_, noise_, b);
}

Misfit Misfit::with_members(int members) const {
  if (!from_budget_) throw std::logic_error("misfit: with_members needs a misfit of a noise budget, without a discrepancy");
  NoiseBudget b = budget_;
  b.members = std::max(members, 1);
  return Misfit(measured_, noise_, b);
}

Misfit::Misfit(const std::vector<TriaxialTest>& measured, const NoiseOptions& noise, const Ensemble& reference,
               int members, Real sim_end, Real sim_balls, const Ensemble& floor) {
  if (!floor.empty() && floor.size() != reference.size())
    throw std::logic_error("misfit: the scatter's floor has other tests");
  if (measured.empty()) throw std::invalid_argument("misfit: no measured tests");
  if (noise.mode != "data" && noise.mode != "lab")
    throw std::invalid_argument("noise '" + noise.mode + "' (allowed: data, lab)");
  if (reference.size() != measured.size()) throw std::logic_error("misfit: the reference ensemble has other tests");
  members_ = std::max(members, 1);
  sim_balls_ = sim_balls;
  for (const auto& runs : reference) {
    Real sum = 0;
    int n = 0;
    for (const TriaxialTest& t : runs)
      if (std::isfinite(t.void_ratio)) sum += t.void_ratio, ++n;
    void_ratio_.push_back(n ? sum / n : kNaN);
  }
  curves_ = !measured.front().q.empty();
  for (const TriaxialTest& t : measured) {
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
    build_curve_noise(measured, noise, reference, sim_balls, floor);
  else
    build_summary_noise(measured, noise, reference, floor);
}

int Misfit::data() const {
  int n = 0;
  for (const auto& f : features_) n += static_cast<int>(f.size());
  return n;
}

void Misfit::build_summary_noise(const std::vector<TriaxialTest>& measured, const NoiseOptions& noise,
                                 const Ensemble& ref, const Ensemble& floor) {
  const bool given = std::any_of(measured.begin(), measured.end(), [](const TriaxialTest& t) {
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
      // The ensemble's scatter of this quantity (sample variance over the members), at least the floor's.
      auto sd_of = [&](const std::vector<TriaxialTest>& runs) {
        Real s = 0, s2 = 0;
        int m = 0;
        for (const TriaxialTest& t : runs) {
          const Real v = quantities(t)[fs[i].quantity];
          if (std::isfinite(v)) s += v, s2 += v * v, ++m;
        }
        return m > 1 ? std::sqrt(std::max(Real(0), (s2 - s * s / m) / (m - 1))) : Real(0);
      };
      fs[i].ensemble_sd = std::max(sd_of(ref[k]), floor.empty() ? Real(0) : sd_of(floor[k]));
      cov(i, i) += fs[i].ensemble_sd * fs[i].ensemble_sd / members_;
    }
    cov_.emplace_back(cov.data(), cov.data() + n * n);
    std::vector<Real> member(static_cast<std::size_t>(n) * n, 0);
    for (int i = 0; i < n; ++i) member[static_cast<std::size_t>(i) * n + i] = fs[i].ensemble_sd * fs[i].ensemble_sd;
    member_cov_.push_back(member);
    for (Real& m : member) m /= members_;  // the data's noise is the lab's or the data's: the ensemble's term alone
    spread_cov_.push_back(member);
  }
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

Real sum_sq(const std::vector<Real>& r, std::size_t from, std::size_t to) {
  Real s = 0;
  for (std::size_t i = from; i < to; ++i) s += r[i] * r[i];
  return s;
}
Real sum_sq(const std::vector<Real>& r) { return sum_sq(r, 0, r.size()); }

Real sum_sq(const std::vector<Real>& r, const std::vector<std::size_t>& at) {
  Real s = 0;
  for (std::size_t i : at) s += r[i] * r[i];
  return s;
}

Real chi2_quantile(Real nu, Real z) {
  const Real a = 2 / (9 * nu);
  return nu * std::pow(1 - a + z * std::sqrt(a), 3);
}

std::vector<Real> Misfit::mean_values(std::size_t k, const std::vector<TriaxialTest>& members) const {
  std::vector<Real> sum(features_[k].size(), 0.0);
  std::vector<int> n(sum.size(), 0);
  for (const TriaxialTest& t : members) {
    const std::vector<Real> v = values(k, t);
    for (std::size_t f = 0; f < v.size(); ++f)
      if (std::isfinite(v[f])) sum[f] += v[f], ++n[f];
  }
  for (std::size_t f = 0; f < sum.size(); ++f) sum[f] = n[f] ? sum[f] / n[f] : kNaN;
  return sum;
}

std::vector<Real> Misfit::test_residuals(std::size_t k, const std::vector<TriaxialTest>& members) const {
  const std::vector<Real> s = mean_values(k, members);
  const int n = static_cast<int>(s.size());
  std::vector<Real> diff(n);
  for (int i = 0; i < n; ++i) diff[i] = s[i] - features_[k][i].measured;
  const Eigen::Map<const Eigen::MatrixXd> cov(cov_[k].data(), n, n);
  return whiten(cov, diff);
}

Real Misfit::member_spread() const {
  Real spread = 0;
  for (std::size_t k = 0; k < cov_.size(); ++k) {
    const int n = static_cast<int>(features_[k].size());
    const Eigen::Map<const Eigen::MatrixXd> cov(cov_[k].data(), n, n), member(member_cov_[k].data(), n, n);
    spread += cov.llt().solve(member).trace();
  }
  // One member less the mean of K that include it: its deviation's variance is (1 - 1/K) of one member's.
  return (1 - 1 / static_cast<Real>(members_)) * spread;
}

SpecimenSpread Misfit::specimen_spread(const Ensemble& scatter) const {
  SpecimenSpread out;
  std::size_t specimens = scatter.front().size();
  for (const auto& runs : scatter) specimens = std::min(specimens, runs.size());
  out.specimen.assign(specimens, {});
  out.ensemble.assign(specimens, {});
  const int all = data();
  out.modelled.assign(static_cast<std::size_t>(all) * all, 0);
  int at = 0;  // the first datum of test k
  for (std::size_t k = 0; k < features_.size(); ++k) {
    out.tests.push_back(at);
    const std::vector<Feature>& fs = features_[k];
    const int n = static_cast<int>(fs.size());
    const Eigen::Map<const Eigen::MatrixXd> cov(cov_[k].data(), n, n), spread(spread_cov_[k].data(), n, n);
    const Eigen::MatrixXd L = Eigen::LLT<Eigen::MatrixXd>(cov).matrixL();
    const auto lower = L.triangularView<Eigen::Lower>();
    // L^-1 C L^-T: the modelled terms in whitened units.
    const Eigen::MatrixXd half = lower.solve(Eigen::MatrixXd(spread));
    const Eigen::MatrixXd w = lower.solve(Eigen::MatrixXd(half.transpose()));
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) out.modelled[static_cast<std::size_t>(at + i) * all + at + j] = w(i, j);
    // The specimen term's scale over one member's: what spread_cov_ holds beside the ensemble's 1/K.
    Eigen::VectorXd scale = Eigen::VectorXd::Zero(n);
    for (int i = 0; i < n; ++i)
      if (fs[i].ensemble_sd > 0) {
        const Real e2 = fs[i].ensemble_sd * fs[i].ensemble_sd;
        scale(i) = std::sqrt(std::max(Real(0), spread(i, i) - e2 / members_) / e2);
      }
    const std::vector<Real> mean = mean_values(k, scatter[k]);
    for (std::size_t s = 0; s < specimens; ++s) {
      const std::vector<Real> v = values(k, scatter[k][s]);
      Eigen::VectorXd d(n);
      for (int i = 0; i < n; ++i) d(i) = std::isfinite(v[i]) && std::isfinite(mean[i]) ? v[i] - mean[i] : 0;
      const Eigen::VectorXd sp = lower.solve(Eigen::VectorXd(scale.cwiseProduct(d)));
      const Eigen::VectorXd en = lower.solve(Eigen::VectorXd(d / std::sqrt(static_cast<Real>(members_))));
      out.specimen[s].insert(out.specimen[s].end(), sp.data(), sp.data() + n);
      out.ensemble[s].insert(out.ensemble[s].end(), en.data(), en.data() + n);
    }
    at += n;
  }
  out.tests.push_back(at);
  return out;
}

std::vector<SpecimenSpread> Misfit::specimen_spreads() const {
  std::vector<SpecimenSpread> out;
  if (!from_budget_) return out;
  for (const Ensemble* e : {&budget_.scatter, &budget_.scatter_floor})
    if (e->size() == features_.size() && !e->empty() &&
        static_cast<int>(e->front().size()) >= kMinSpreadSpecimens)
      out.push_back(specimen_spread(*e));
  return out;
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
