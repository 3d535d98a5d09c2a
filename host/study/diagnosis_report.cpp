#include "host/study/diagnosis_report.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>

#include "host/data/curve_reading.hpp"
#include "host/fit/calibration_report.hpp"
#include "host/io/io_hdf5.hpp"
#include "host/util/text_format.hpp"

namespace dem {

namespace {

/// The extension a diagnosis reports against the base: the one its verdict names first, else the best by BIC
/// (a candidate, to show what it would change).
const ExtensionFit* top_fit(const Diagnosis& dg) {
  const ExtensionFit* top = nullptr;
  for (const ExtensionFit& f : dg.fits)
    if (dg.verdict.rfind(f.ext.name, 0) == 0) return &f;
  for (const ExtensionFit& f : dg.fits)
    if (!top || f.bic < top->bic) top = &f;
  return top;
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
  if (base.r.size() > first) {  // a joint fit's compression tests (JointTerm), after the triaxial data
    const std::pair<Real, Real> c{sum_sq(base.r, first, base.r.size()), sum_sq(ext.r, first, ext.r.size())};
    for (auto* t : {&by_pressure, &by_range, &by_quantity}) at(*t, "compression tests") = c;
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

/// The report's line on the specimens' state.
std::string state_text(const Session& ss, const Misfit& m, const std::vector<TriaxialTest>& tests) {
  const StateMatch& state = ss.state;
  if (state.tests == 0)
    return "The data give no void ratio: the simulator's specimens have the density their preparation gives (" +
           fmt("e = %.3f", ss.lab.prepared_void_ratio(0)) + " for the first), and the calibrated friction absorbs "
           "any difference in density.\n";
  std::string s = "The simulator's specimens were prepared to the data's void ratio " + fmt("%.4f", state.target) +
                  " (preparation friction " + fmt("%.4g", state.prep_mu_s) + ", which packs " +
                  fmt("%.4f", state.reached) +
                  fmt(" on the mean of its first %.0f", static_cast<double>(state.specimens)) +
                  "). At the start of shear, measured and simulated (mean of the scatter specimens at the base "
                  "model):";
  for (std::size_t k = 0; k < tests.size(); ++k)
    s += fmt(" %g kPa", 1e-3 * tests[k].sigma3) + fmt(" %.4f", tests[k].void_ratio) +
         fmt(" against %.4f;", m.reached_void_ratio(k));
  return s + "\n";
}

}  // namespace

std::string edge_names(const CalibrationResult& r) {
  std::string edge;
  for (const std::string& name : r.at_edge()) edge += (edge.empty() ? "" : ", ") + name;
  return edge;
}

DiagnosisReport::DiagnosisReport(const Session& ss, const Config& base, const CalibrationOptions& o) : ss_(ss) {
  std::ostream& md = md_;
  md << "# Diagnosis of " << o.data << "\n\n"
     << "Simulator: the cell triaxial test in " << ss.cell_text() << ", an ensemble of " << ss.lab.members()
     << " specimens of " << ss.lab.balls() << " balls (packing seeds from " << base.run.seed
     << "), each prepared once; every parameter point runs them all and compares their mean. Free base parameters:";
  for (const FreeParam& f : ss.in.free) md << " " << f.name;
  md << ". Misfit: chi2 over " << (ss.in.data.curves ? "q and eps_v at fixed axial strains (0.02% to 15%)"
                                                  : "the summary quantities given")
     << ", with the data's noise, the measured specimen's own scatter and the simulator's standard error "
        "(host/fit/misfit.hpp); noise: " << (ss.in.noise.mode == "lab" ? ss.in.noise.lab_name : "the data's") << ".\n\n";
  if (!ss.in.ref.values.empty())
    md << "Reference values: " << ss.in.ref.path << (ss.in.ref.comment.empty() ? "" : ": " + ss.in.ref.comment)
       << " The calibrated values belong to this simulator (its cell, density and boundary), the reference values to "
          "the model they were calibrated with: a difference between them measures the two simulators as much as "
          "the data.\n\n";
  for (const std::string& n : ss.in.data.notes) md << "Note on the data: " << n << "\n\n";
  csv_ << "material,model,parameter,value,chi2,bic,heldout_chi2,runs\n";
}

/// The table of the base model and each extension fit (parameters, chi2, BIC, held-out chi2, runs), into the report
/// and as rows of models.csv.
void DiagnosisReport::models_table(const std::string& material, const Diagnosis& dg, std::size_t tests) {
  const Session& ss = ss_;
  std::ostream& md = md_;
  std::ostream& csv = csv_;
  md << "| model | parameters | chi2 | BIC | held-out chi2 | runs |\n|---|---|---|---|---|---|\n| base | ";
  for (std::size_t k = 0; k < ss.in.free.size(); ++k) {
    md << ss.in.free[k].name << " = " << fmt("%.4g", ss.in.free[k].shown * dg.base.values[k]) << " ";
    csv << material << ",base," << ss.in.free[k].name << "," << fmt("%.6g", ss.in.free[k].shown * dg.base.values[k]) << ","
        << fmt("%.3f", dg.base.best.chi2) << "," << fmt("%.3f", dg.base_bic) << "," << fmt("%.3f", dg.base_heldout)
        << "," << dg.base.design.size() * tests << "\n";
  }
  md << "| " << fmt("%.1f", dg.base.best.chi2) << " | " << fmt("%.1f", dg.base_bic) << " | "
     << fmt("%.1f", dg.base_heldout) << " | " << dg.base.design.size() * tests * ss.lab.members() << " |\n";
  for (const ExtensionFit& f : dg.fits) {
    md << "| " << f.ext.name << " | ";
    for (std::size_t k = 0; k < ss.in.free.size(); ++k)
      md << ss.in.free[k].name << " = " << fmt("%.4g", ss.in.free[k].shown * f.values[k]) << " ";
    const Real shown = free_param(f.ext.param).shown;
    md << f.ext.param << " = " << fmt("%.3g", shown * f.strength) << " | " << fmt("%.1f", f.best.chi2) << " | "
       << fmt("%.1f", f.bic) << " | " << fmt("%.1f", f.heldout) << " | " << f.runs << " |\n";
    csv << material << "," << f.ext.name << "," << f.ext.param << "," << fmt("%.6g", shown * f.strength) << ","
        << fmt("%.3f", f.best.chi2) << "," << fmt("%.3f", f.bic) << "," << fmt("%.3f", f.heldout) << "," << f.runs
        << "\n";
  }
  // The generic discrepancies, each extension's rival: fitted over the base's runs, no runs of their own.
  for (const GenericFit& g : dg.generic) {
    md << "| generic: " << g.shape.name << " | ";
    for (std::size_t k = 0; k < ss.in.free.size(); ++k)
      md << ss.in.free[k].name << " = " << fmt("%.4g", ss.in.free[k].shown * g.values[k]) << " ";
    md << "c = " << fmt("%.3g", g.c) << " in " << g.shape.formula << " | " << fmt("%.1f", g.chi2) << " | "
       << fmt("%.1f", g.bic) << " | " << fmt("%.1f", g.heldout) << " | 0 |\n";
    csv << material << ",generic: " << g.shape.name << ",c," << fmt("%.6g", g.c) << "," << fmt("%.3f", g.chi2) << ","
        << fmt("%.3f", g.bic) << "," << fmt("%.3f", g.heldout) << ",0\n";
  }
}

/// The calibrated values beside the reference values, for the base model and the extension the verdict names.
std::string DiagnosisReport::reference_table(const std::string& material, const Diagnosis& dg) const {
  const Session& ss = ss_;
  if (ss.in.ref.values.empty()) return "";
  std::ostringstream md;
  const ExtensionFit* named = nullptr;  // the extension the verdict names first, if any
  for (const ExtensionFit& f : dg.fits)
    if (dg.verdict.rfind(f.ext.name, 0) == 0) named = &f;
  md << "\nCalibrated values beside the reference (" << ss.in.ref.path << "):\n\n| parameter | base model | "
     << (named ? "base + " + named->ext.name + " | " : "") << "reference |\n|---|---|" << (named ? "---|" : "")
     << "---|\n";
  for (std::size_t k = 0; k < ss.in.free.size(); ++k) {
    const Real ref = ss.reference(material, ss.in.free[k].name);
    md << "| " << ss.in.free[k].name << " | " << fmt("%.4g", ss.in.free[k].shown * dg.base.values[k]) << " | "
       << (named ? fmt("%.4g", ss.in.free[k].shown * named->values[k]) + " | " : "")
       << (std::isfinite(ref) ? fmt("%g", ref) : std::string("-")) << " |\n";
  }
  return md.str();
}


const ExtensionFit* DiagnosisReport::add_material(const std::string& material, const std::vector<TriaxialTest>& tests,
                                                  const Misfit& misfit, const Diagnosis& dg) {
  std::string widened;
  for (const std::string& note : dg.base.widened) widened += (widened.empty() ? "" : "; ") + note;
  const std::string edge = edge_names(dg.base);
  md_ << "## " << material << "\n\n"
      << (misfit.cell_bias_finding().empty() ? "" : "**Finding: the cell's bias.** " + misfit.cell_bias_finding() + "\n\n")
      << "**Verdict: " << dg.verdict << ".** " << dg.explanation << "\n\n"
      << noise_table(misfit, tests)
      << (widened.empty() ? "" : "Search ranges: " + widened + ".\n\n")
      << (edge.empty() ? "" : "**Warning:** the base model's " + edge + " lies at the edge of its search range: the "
                              "optimum may lie outside, and part of the misfit may be the range's, not the model's.\n\n");
  models_table(material, dg, tests.size());
  md_ << reference_table(material, dg);
  md_ << "\nEach extension against the base model, and, where it passes, against the generic discrepancy of lowest BIC "
         "(a shape with no physics and one parameter, fitted over the base's runs: an extension is named only where "
         "it beats that rival by the same margins, docs/calibration.md, Diagnosis):\n\n";
  for (const ExtensionFit& f : dg.fits) md_ << "- **" << f.ext.name << "**: " << f.reason << "\n";
  for (const std::string& n : dg.notes) md_ << "- " << n << "\n";
  md_ << "\nThe base model's calibrated values:\n\n```\n" << uncertainty_text(dg.base, material, "diagnose")
      << "```\n";
  md_ << "\n" << state_text(ss_, misfit, tests);
  const ExtensionFit* top = top_fit(dg);
  if (top)
    md_ << gain_tables(misfit, tests, dg.base.best, top->best,
                       top->ext.name + (dg.verdict == "none" ? " (candidate, not named)" : ""));
  md_ << "\n";
  return top;
}

void DiagnosisReport::close() {
  if (ss_.lab.failed_runs() > 0) md_ << "**Warning:** " << ss_.failed_text() << ".\n\n";
  md_ << "![measured and simulated: the base model in full lines, the extended one dashed](calibration.png)\n";
}

void DiagnosisReport::write(const std::string& prediction) const {
  io::write_text_atomic(ss_.report.folder + "/diagnosis.md", md_.str() + (prediction.empty() ? "" : "\n" + prediction));
  io::write_text_atomic(ss_.report.folder + "/models.csv", csv_.str());
}

}  // namespace dem
