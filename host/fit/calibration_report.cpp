#include "host/fit/calibration_report.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>

#include "host/util/text_format.hpp"

namespace dem {

/// The errors table (like the paper's Table 6): measured, simulated and error per test and quantity.
namespace {

/// The errors table's rows, their cells as written: material, sigma3 (kPa), quantity, unit, measured, simulated,
/// error (%). One source for the CSV and the printed table.
std::vector<std::array<std::string, 7>> error_rows(const std::vector<TriaxialTest>& meas,
                                                   const std::vector<TriaxialTest>& sim) {
  std::vector<std::array<std::string, 7>> rows;
  for (std::size_t k = 0; k < meas.size(); ++k) {
    const auto m = quantities(meas[k]), q = quantities(sim[k]);
    for (int i = 0; i < kQuantities; ++i) {
      if (!std::isfinite(m[i])) continue;
      rows.push_back({meas[k].material, fmt("%g", 1e-3 * meas[k].sigma3), quantity_name(i),
                      in_table_unit(i, m[i]).second, fmt("%.5g", in_table_unit(i, m[i]).first),
                      fmt("%.5g", in_table_unit(i, q[i]).first),
                      // No relative error of a measured 0 (a test without dilatancy): empty, not -nan or inf.
                      m[i] != 0 && std::isfinite(q[i]) ? fmt("%.2f", 100 * (q[i] - m[i]) / std::fabs(m[i])) : ""});
    }
  }
  return rows;
}

}  // namespace

std::string errors_csv(const std::vector<TriaxialTest>& meas, const std::vector<TriaxialTest>& sim) {
  std::string s = "material,sigma3_kPa,quantity,unit,measured,simulated,error_pct\n";
  for (const auto& c : error_rows(meas, sim)) {
    for (std::size_t j = 0; j < c.size(); ++j) s += (j ? "," : "") + c[j];
    s += "\n";
  }
  return s;
}

void print_errors(const std::vector<TriaxialTest>& meas, const std::vector<TriaxialTest>& sim) {
  std::printf("%-10s %7s %-14s %12s %12s %8s\n", "material", "s3 kPa", "quantity", "measured", "simulated", "err %");
  for (const auto& c : error_rows(meas, sim))
    std::printf("%-10s %7s %-14s %12s %12s %8s\n", c[0].c_str(), c[1].c_str(), (c[2] + " " + c[3]).c_str(),
                c[4].c_str(), c[5].c_str(), c[6].c_str());
}

/// The calibrated values with their 95% intervals and correlations, in lines prefixed "<job>: <material>: ".
std::string uncertainty_text(const CalibrationResult& r, const std::string& material, const std::string& job) {
  std::ostringstream o;
  const std::string at = job + ": " + material + ": ";
  for (std::size_t k = 0; k < r.free.size() && k < r.interval.size(); ++k)
    o << at << r.free[k].name << " = " << fmt("%.4g", r.free[k].shown * r.values[k]) << ", 95% interval ["
      << fmt("%.4g", r.free[k].shown * r.interval[k].first) << ", " << fmt("%.4g", r.free[k].shown * r.interval[k].second)
      << "]\n";
  for (std::size_t a = 0; a < r.correlation.size(); ++a)
    for (std::size_t b = a + 1; b < r.correlation.size(); ++b)
      o << at << "correlation of " << r.free[a].name << " and " << r.free[b].name << ": "
        << fmt("%+.2f", r.correlation[a][b]) << "\n";
  for (const std::string& p : r.inseparable())
    o << at << "these data cannot separate " << p << ": they trade against each other (in strength, for friction)\n";
  if (!r.spreads.empty()) {
    o << at << "the intervals measured on the scatter specimens (their departures in place of the modelled specimen "
      << "and ensemble noise): the rise of";
    for (std::size_t k = 0; k < r.free.size() && k < r.rise_factor.size(); ++k)
      o << " " << r.free[k].name << fmt(" x%.2f,", r.rise_factor[k]);
    o << " of the joint region" << fmt(" x%.2f", r.region_factor) << " the misfit's own\n";
  }
  if (r.scale > 1)
    o << at << "the misfit exceeds the noise (chi2 / dof " << fmt("%.2f", r.scale)
      << "): the intervals are widened by its square root\n";
  o << at << r.design.size() << " parameter points run to find the optimum; the chi2 stays within the joint 95% rise "
    << "of its best over " << fmt("%.0f", 100 * r.flat_share()) << "% of the searched ranges ("
    << (r.flat_share() > 0.25 ? "a flat minimum: the data hardly constrain these parameters" : "a defined minimum")
    << ")\n";
  return o.str();
}

std::string reference_text(const CalibrationResult& r, const std::vector<Real>& reference, Real run_chi2,
                           const std::string& material, const std::string& job) {
  std::vector<Real> si;
  std::string at;
  for (std::size_t k = 0; k < r.free.size(); ++k) {
    si.push_back(reference[k] / r.free[k].shown);
    at += (k ? ", " : "") + r.free[k].name + fmt(" %.4g", reference[k]);
  }
  const Real rise = r.region_rise(si);
  std::string o = job + ": " + material + ": the reference point (" + at + ") ";
  o += std::isfinite(rise) ? fmt("lies at %.2f of the joint 95%% region's rise: ", rise) +
                                 (rise <= 1 ? "inside the region" : "outside the region")
                           : std::string("lies outside the searched ranges");
  if (std::isfinite(run_chi2))
    o += fmt("; run: chi2 %.1f", run_chi2) + fmt(" against the best's %.1f", r.best.chi2) +
         fmt(" (the region's rise: %.1f)", chi2_95(static_cast<int>(r.free.size())) * r.scale * r.region_factor);
  return o + "\n";
}

/// The noise used, per test and quantity: the median over the test's features of each part.
std::string noise_table(const Misfit& mf, const std::vector<TriaxialTest>& tests) {
  std::ostringstream md;
  md << "Noise (" << mf.source() << "; median standard deviation over each test's data; the simulator's is that of "
     << "the mean of " << mf.members() << " specimens"
     << (mf.sim_balls() > 0 ? fmt(" of %.0f balls", mf.sim_balls()) : std::string())
     << "; correlation length along strain " << fmt("%.2f", mf.correlation_length()) << " in ln strain):\n\n| sigma3 kPa | quantity | data | measured specimen | "
        "simulator mean | simulator cell |\n|---|---|---|---|---|---|\n";
  for (std::size_t k = 0; k < mf.tests(); ++k) {
    std::map<std::string, std::vector<std::array<Real, 4>>> by;
    for (const Feature& f : mf.features(k)) {
      const std::string q = f.strain > 0 ? quantity_group(f) + (f.quantity == 0 ? " (kPa)" : " (%)") : f.name;
      const Real u = feature_unit(f, 1).first;
      by[q].push_back({u * f.data_sd, u * f.specimen_sd, u * f.ensemble_sd / std::sqrt(Real(mf.members())), u * f.cell_sd});
    }
    for (auto& [q, v] : by) {
      md << "| " << fmt("%g", 1e-3 * tests[k].sigma3) << " | " << q;
      for (int c = 0; c < 4; ++c) {
        std::vector<Real> x;
        for (const auto& a : v) x.push_back(a[c]);
        std::nth_element(x.begin(), x.begin() + x.size() / 2, x.end());
        md << " | " << fmt("%.3g", x[x.size() / 2]);
      }
      md << " |\n";
    }
  }
  md << "\n";
  for (const std::string& n : mf.notes()) md << "- " << n << "\n";
  return md.str() + "\n";
}

/// The gain in markdown: chi2 of the base and the extended model by pressure, by strain range and by quantity,
/// then every datum. Strain ranges: small (up to 0.2%), hardening (to 3%), large (beyond); summary data: E_ini
/// and q at 1% small, q at 3%, the peak and its strain hardening, q_end and dilatancy large.
std::string gain_tables(const Misfit& mf, const std::vector<TriaxialTest>& tests, const Evaluation& base,
                        const Evaluation& ext, const std::string& name) {
  static const char* range_of[kQuantities] = {"small strain", "small strain", "hardening", "hardening",
                                              "hardening", "large strain", "large strain"};
  using Groups = std::vector<std::pair<std::string, std::pair<Real, Real>>>;  // in the order first met
  Groups by_pressure, by_range, by_quantity;
  auto at = [](Groups& g, const std::string& key) -> std::pair<Real, Real>& {
    for (auto& [k, v] : g)
      if (k == key) return v;
    return g.emplace_back(key, std::pair<Real, Real>{0, 0}).second;
  };
  std::ostringstream rows;
  std::size_t first = 0;
  for (std::size_t k = 0; k < mf.tests(); ++k) {
    const std::vector<Real> b = mf.mean_values(k, {base.sim[k]}), e = mf.mean_values(k, {ext.sim[k]});
    const std::string p = fmt("%g kPa", 1e-3 * tests[k].sigma3);
    for (std::size_t i = 0; i < mf.features(k).size(); ++i) {
      const Feature& f = mf.features(k)[i];
      const Real cb = base.r[first + i] * base.r[first + i], ce = ext.r[first + i] * ext.r[first + i];
      const bool summary = f.strain == 0;
      const std::string range = summary ? range_of[f.quantity]
                                        : f.strain <= 0.002 ? "small strain" : f.strain <= 0.03 ? "hardening"
                                                                                                 : "large strain";
      const std::string quantity = summary ? f.name : f.quantity == 0 ? "q" : "eps_v";
      for (auto* t : {&by_pressure, &by_range, &by_quantity}) {
        const std::string key = t == &by_pressure ? p : t == &by_range ? range : quantity;
        at(*t, key).first += cb;
        at(*t, key).second += ce;
      }
      const Real s = mf.sd(k, i);
      const auto u = feature_unit(f, f.measured);
      rows << "| " << fmt("%g", 1e-3 * tests[k].sigma3) << " | " << f.name << " | " << u.second << " | "
           << fmt("%.4g", u.first) << " | " << fmt("%.4g", feature_unit(f, b[i]).first) << " | "
           << fmt("%+.1f", (b[i] - f.measured) / s) << " | " << fmt("%.4g", feature_unit(f, e[i]).first) << " | "
           << fmt("%+.1f", (e[i] - f.measured) / s) << " |\n";
    }
    first += mf.features(k).size();
  }
  std::ostringstream md;
  md << "\nMisfit (chi2) of the base model and of the base + " << name
     << " model, from the whitened residuals (each datum counts what it says beyond those before it in the "
        "test, q before eps_v, small strain first), so that the groups add up to chi2:\n\n"
        "| by | group | base | + " << name
     << " |\n|---|---|---|---|\n";
  for (const auto& [what, table] : {std::make_pair("pressure", &by_pressure), std::make_pair("strain range", &by_range),
                                    std::make_pair("quantity", &by_quantity)})
    for (const auto& [key, c] : *table)
      md << "| " << what << " | " << key << " | " << fmt("%.1f", c.first) << " | " << fmt("%.1f", c.second) << " |\n";
  md << "\nEvery datum (plain residual in units of its whole noise, (simulated - measured) / s):\n\n| sigma3 kPa | "
        "datum | unit | measured | base | residual | + " << name << " | residual |\n|---|---|---|---|---|---|---|---|\n"
     << rows.str();
  return md.str();
}

}  // namespace dem
