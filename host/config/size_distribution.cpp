#include "host/config/size_distribution.hpp"

#include "host/config/toml_reader.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace dem {

namespace {

/// The lognormal's cut in standard deviations of ln(d) by mass.
constexpr Real kLognormalCut = 3;

Real phi(Real z) { return 0.5 * std::erfc(-z / std::sqrt(Real(2))); }

/// z with phi(z) = p in [phi(lo), phi(hi)], by bisection: exact to rounding, and called once a ball.
Real phi_inverse(Real p, Real lo, Real hi) {
  for (int k = 0; k < 80 && hi - lo > 1e-14; ++k) {
    const Real mid = 0.5 * (lo + hi);
    (phi(mid) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace

SizeDistribution::SizeDistribution(const ParticleConfig& pc) : law_(pc.psd) {
  switch (law_) {
    case SizeLaw::uniform:
      // The spread about the mean diameter: d_min and d_max with mean (d_min + d_max) / 2 = diameter.
      dmax_ = 2 * pc.diameter * pc.diameter_ratio / (1 + pc.diameter_ratio);
      dmin_ = dmax_ / pc.diameter_ratio;
      mean_ = pc.diameter;
      mean_cube_ = dmax_ - dmin_ < 1e-12 * dmax_
                       ? pc.diameter * pc.diameter * pc.diameter
                       : (std::pow(dmax_, 4) - std::pow(dmin_, 4)) / (4 * (dmax_ - dmin_));
      return;
    case SizeLaw::lognormal: {
      if (!(pc.median > 0) || !(pc.log_sd > 0)) throw std::invalid_argument("lognormal: median and log_sd must be > 0");
      sd_ = pc.log_sd;
      median_n_ = pc.median * std::exp(-3 * sd_ * sd_);
      zlo_ = -kLognormalCut + 3 * sd_;  // the cut by mass, in the number distribution's z
      zhi_ = kLognormalCut + 3 * sd_;
      dmin_ = pc.median * std::exp(-kLognormalCut * sd_);
      dmax_ = pc.median * std::exp(kLognormalCut * sd_);
      plo_ = phi(zlo_);
      pspan_ = phi(zhi_) - plo_;
      // Means of the truncated number distribution: by the midpoint rule on 4,000 quantiles, to 1e-7.
      constexpr int kPoints = 4000;
      Real s1 = 0, s3 = 0;
      for (int k = 0; k < kPoints; ++k) {
        const Real d = diameter((k + 0.5) / kPoints);
        s1 += d;
        s3 += d * d * d;
      }
      mean_ = s1 / kPoints;
      mean_cube_ = s3 / kPoints;
      return;
    }
    case SizeLaw::sieve: {
      sieve_ = pc.sieve;
      passing_ = pc.passing;
      const std::size_t n = sieve_.size();
      if (n < 2 || passing_.size() != n || passing_.front() != 0 || passing_.back() != 1)
        throw std::invalid_argument("sieve: at least two sieves, passing from 0 to 100%");
      for (std::size_t i = 1; i < n; ++i)
        if (!(sieve_[i] > sieve_[i - 1]) || passing_[i] < passing_[i - 1])
          throw std::invalid_argument("sieve: sizes increasing and passing not decreasing");
      // Between sieves a and b the mass w is spread evenly in d, so the number density is w / (b - a) / d^3 (a
      // ball's mass goes as d^3): its number sum (w / (b - a)) (a^-2 - b^-2) / 2, its mean 2ab / (a + b), its mean
      // of d^3 2 a^2 b^2 / (a + b).
      count_.assign(n, 0);
      Real total = 0, s1 = 0, s3 = 0;
      for (std::size_t i = 1; i < n; ++i) {
        const Real a = sieve_[i - 1], b = sieve_[i], w = passing_[i] - passing_[i - 1];
        const Real number = w / (b - a) * (1 / (a * a) - 1 / (b * b)) / 2;
        total += number;
        count_[i] = total;
        s1 += number * 2 * a * b / (a + b);
        s3 += number * 2 * a * a * b * b / (a + b);
      }
      for (Real& c : count_) c /= total;
      mean_ = s1 / total;
      mean_cube_ = s3 / total;
      // The sizes drawn: from the first sieve with mass above it to the last below which all of it lies.
      std::size_t lo = 0, hi = n - 1;
      while (lo + 1 < n && passing_[lo + 1] == 0) ++lo;
      while (hi > 0 && passing_[hi - 1] == 1) --hi;
      dmin_ = sieve_[lo];
      dmax_ = sieve_[hi];
      return;
    }
  }
}

Real SizeDistribution::diameter(Real u) const {
  switch (law_) {
    case SizeLaw::uniform:
      return dmin_ + (dmax_ - dmin_) * u;
    case SizeLaw::lognormal: {
      return median_n_ * std::exp(sd_ * phi_inverse(plo_ + u * pspan_, zlo_, zhi_));
    }
    case SizeLaw::sieve: {
      std::size_t i = 1;
      while (i + 1 < count_.size() && (count_[i] <= u || count_[i] == count_[i - 1])) ++i;
      const Real a = sieve_[i - 1], b = sieve_[i];
      const Real v = count_[i] > count_[i - 1] ? (u - count_[i - 1]) / (count_[i] - count_[i - 1]) : 0;
      // The quantile of the density d^-3 on [a, b]: (a^-2 - v (a^-2 - b^-2))^(-1/2).
      const Real ia = 1 / (a * a), ib = 1 / (b * b);
      return 1 / std::sqrt(ia - std::clamp(v, Real(0), Real(1)) * (ia - ib));
    }
  }
  return mean_;
}

Real SizeDistribution::passing(Real d) const {
  switch (law_) {
    case SizeLaw::uniform: {
      if (d <= dmin_) return 0;
      if (d >= dmax_) return 1;
      return (std::pow(d, 4) - std::pow(dmin_, 4)) / (std::pow(dmax_, 4) - std::pow(dmin_, 4));
    }
    case SizeLaw::lognormal: {
      const Real z = std::log(d / (median_n_ * std::exp(3 * sd_ * sd_))) / sd_;  // by mass
      const Real lo = phi(-kLognormalCut), hi = phi(kLognormalCut);
      return std::clamp((phi(z) - lo) / (hi - lo), Real(0), Real(1));
    }
    case SizeLaw::sieve: {
      if (d <= sieve_.front()) return 0;
      if (d >= sieve_.back()) return 1;
      std::size_t i = 1;
      while (sieve_[i] < d) ++i;
      const Real t = (d - sieve_[i - 1]) / (sieve_[i] - sieve_[i - 1]);
      return passing_[i - 1] + t * (passing_[i] - passing_[i - 1]);
    }
  }
  return 0;
}

Real SizeDistribution::number_passing(Real d) const {
  switch (law_) {
    case SizeLaw::uniform:
      return dmax_ > dmin_ ? std::clamp((d - dmin_) / (dmax_ - dmin_), Real(0), Real(1)) : (d >= dmin_ ? 1 : 0);
    case SizeLaw::lognormal: {
      const Real z = std::clamp(std::log(d / median_n_) / sd_, zlo_, zhi_);
      return (phi(z) - plo_) / pspan_;
    }
    case SizeLaw::sieve: {
      if (d <= sieve_.front()) return 0;
      if (d >= sieve_.back()) return 1;
      std::size_t i = 1;
      while (sieve_[i] < d) ++i;
      const Real a = sieve_[i - 1], b = sieve_[i];
      const Real part = (1 / (a * a) - 1 / (d * d)) / (1 / (a * a) - 1 / (b * b));
      return count_[i - 1] + part * (count_[i] - count_[i - 1]);
    }
  }
  return 0;
}

void read_size_distribution(TableReader& pt, ParticleConfig& pc) {
  std::string psd = "uniform";
  pt.string("psd", psd, {"uniform", "lognormal", "sieve"});
  pc.psd = psd == "lognormal" ? SizeLaw::lognormal : psd == "sieve" ? SizeLaw::sieve : SizeLaw::uniform;
  pt.number("median_mm", pc.median, 1e-6, 1e6, 1e-3, true);
  pt.number("log_sd", pc.log_sd, 0, 1, 1, true);
  pt.numbers("sieve_mm", pc.sieve, 1e-6, 1e6, 1e-3);
  pt.numbers("passing_pct", pc.passing, 0, 100, 0.01);
  const std::vector<std::pair<const char*, SizeLaw>> own = {
      {"diameter_mm", SizeLaw::uniform}, {"diameter_ratio", SizeLaw::uniform}, {"median_mm", SizeLaw::lognormal},
      {"log_sd", SizeLaw::lognormal},    {"sieve_mm", SizeLaw::sieve},         {"passing_pct", SizeLaw::sieve}};
  for (const auto& [key, law] : own) {
    if (pt.has(key) && law != pc.psd)
      pt.fail(key, "not with psd = \"" + psd + "\" (it belongs to psd = \"" +
                       (law == SizeLaw::uniform ? "uniform" : law == SizeLaw::lognormal ? "lognormal" : "sieve") +
                       "\")");
    if (!pt.has(key) && law == pc.psd && law != SizeLaw::uniform)
      pt.fail(key, "missing: psd = \"" + psd + "\" needs it");
  }
  if (pc.psd == SizeLaw::sieve) {
    if (pc.sieve.size() < 2) pt.fail("sieve_mm", "at least two sieves");
    if (pc.passing.size() != pc.sieve.size())
      pt.fail("passing_pct", "one value a sieve (" + std::to_string(pc.sieve.size()) + " sieves, " +
                                 std::to_string(pc.passing.size()) + " values)");
    for (std::size_t i = 1; i < pc.sieve.size(); ++i) {
      if (!(pc.sieve[i] > pc.sieve[i - 1])) pt.fail("sieve_mm", "the sizes must increase");
      if (pc.passing[i] < pc.passing[i - 1]) pt.fail("passing_pct", "the percentages must not decrease");
    }
    if (pc.passing.front() != 0 || pc.passing.back() != 1)
      pt.fail("passing_pct", "must run from 0 (the smallest sieve holds everything) to 100 (the largest passes all)");
  }
  if (pc.psd != SizeLaw::uniform) pc.diameter = SizeDistribution(pc).mean();
}

std::string size_text(const ParticleConfig& pc) {
  const SizeDistribution sizes(pc);
  std::ostringstream t;
  t.precision(3);
  const Real lo = 1e3 * sizes.smallest(), hi = 1e3 * sizes.largest(), mean = 1e3 * sizes.mean();
  switch (pc.psd) {
    case SizeLaw::uniform:
      if (hi - lo < 1e-9 * hi) t << mean << " mm";
      else t << lo << " to " << hi << " mm (uniform)";
      break;
    case SizeLaw::lognormal:
      t << "lognormal by mass, D50 " << 1e3 * pc.median << " mm, log_sd " << pc.log_sd << ": " << lo << " to " << hi
        << " mm, mean " << mean << " mm";
      break;
    case SizeLaw::sieve:
      t << "a sieve table by mass: " << lo << " to " << hi << " mm, mean " << mean << " mm";
      break;
  }
  return t.str();
}

std::string size_key(const ParticleConfig& pc) {
  if (pc.psd == SizeLaw::uniform) return "";
  std::ostringstream k;
  k.precision(17);
  if (pc.psd == SizeLaw::lognormal) {
    k << " psd lognormal " << pc.median << " " << pc.log_sd;
  } else {
    k << " psd sieve";
    for (std::size_t i = 0; i < pc.sieve.size(); ++i) k << " " << pc.sieve[i] << ":" << pc.passing[i];
  }
  return k.str();
}

}  // namespace dem
