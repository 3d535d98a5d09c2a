#include "host/fit/calibration_report.hpp"

#include <array>
#include <cmath>
#include <cstdio>
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

}  // namespace dem
