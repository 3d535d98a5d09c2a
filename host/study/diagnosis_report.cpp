#include "host/study/diagnosis_report.hpp"

#include <cmath>
#include <cstdio>

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
  for (const FreeParam& f : ss.free) md << " " << f.name;
  md << ". Misfit: chi2 over " << (ss.data.curves ? "q and eps_v at fixed axial strains (0.02% to 15%)"
                                                  : "the summary quantities given")
     << ", with the data's noise, the measured specimen's own scatter and the simulator's standard error "
        "(host/fit/misfit.hpp); noise: " << (ss.noise.mode == "lab" ? ss.noise.lab_name : "the data's") << ".\n\n";
  if (!ss.ref.values.empty())
    md << "Reference values: " << ss.ref.path << (ss.ref.comment.empty() ? "" : ": " + ss.ref.comment)
       << " The calibrated values belong to this simulator (its cell, density and boundary), the reference values to "
          "the model they were calibrated with: a difference between them measures the two simulators as much as "
          "the data.\n\n";
  for (const std::string& n : ss.data.notes) md << "Note on the data: " << n << "\n\n";
  csv_ << "material,model,parameter,value,chi2,bic,heldout_chi2,runs\n";
}

/// The table of the base model and each extension fit (parameters, chi2, BIC, held-out chi2, runs), into the report
/// and as rows of models.csv.
void DiagnosisReport::models_table(const std::string& material, const Diagnosis& dg, std::size_t tests) {
  const Session& ss = ss_;
  std::ostream& md = md_;
  std::ostream& csv = csv_;
  md << "| model | parameters | chi2 | BIC | held-out chi2 | runs |\n|---|---|---|---|---|---|\n| base | ";
  for (std::size_t k = 0; k < ss.free.size(); ++k) {
    md << ss.free[k].name << " = " << fmt("%.4g", ss.free[k].shown * dg.base.values[k]) << " ";
    csv << material << ",base," << ss.free[k].name << "," << fmt("%.6g", ss.free[k].shown * dg.base.values[k]) << ","
        << fmt("%.3f", dg.base.best.chi2) << "," << fmt("%.3f", dg.base_bic) << "," << fmt("%.3f", dg.base_heldout)
        << "," << dg.base.design.size() * tests << "\n";
  }
  md << "| " << fmt("%.1f", dg.base.best.chi2) << " | " << fmt("%.1f", dg.base_bic) << " | "
     << fmt("%.1f", dg.base_heldout) << " | " << dg.base.design.size() * tests * ss.lab.members() << " |\n";
  for (const ExtensionFit& f : dg.fits) {
    md << "| " << f.ext.name << " | ";
    for (std::size_t k = 0; k < ss.free.size(); ++k)
      md << ss.free[k].name << " = " << fmt("%.4g", ss.free[k].shown * f.values[k]) << " ";
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
    for (std::size_t k = 0; k < ss.free.size(); ++k)
      md << ss.free[k].name << " = " << fmt("%.4g", ss.free[k].shown * g.values[k]) << " ";
    md << "c = " << fmt("%.3g", g.c) << " in " << g.shape.formula << " | " << fmt("%.1f", g.chi2) << " | "
       << fmt("%.1f", g.bic) << " | " << fmt("%.1f", g.heldout) << " | 0 |\n";
    csv << material << ",generic: " << g.shape.name << ",c," << fmt("%.6g", g.c) << "," << fmt("%.3f", g.chi2) << ","
        << fmt("%.3f", g.bic) << "," << fmt("%.3f", g.heldout) << ",0\n";
  }
}

/// The calibrated values beside the reference values, for the base model and the extension the verdict names.
std::string DiagnosisReport::reference_table(const std::string& material, const Diagnosis& dg) const {
  const Session& ss = ss_;
  if (ss.ref.values.empty()) return "";
  std::ostringstream md;
  const ExtensionFit* named = nullptr;  // the extension the verdict names first, if any
  for (const ExtensionFit& f : dg.fits)
    if (dg.verdict.rfind(f.ext.name, 0) == 0) named = &f;
  md << "\nCalibrated values beside the reference (" << ss.ref.path << "):\n\n| parameter | base model | "
     << (named ? "base + " + named->ext.name + " | " : "") << "reference |\n|---|---|" << (named ? "---|" : "")
     << "---|\n";
  for (std::size_t k = 0; k < ss.free.size(); ++k) {
    const Real ref = ss.reference(material, ss.free[k].name);
    md << "| " << ss.free[k].name << " | " << fmt("%.4g", ss.free[k].shown * dg.base.values[k]) << " | "
       << (named ? fmt("%.4g", ss.free[k].shown * named->values[k]) + " | " : "")
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
  md_ << "\n" << ss_.state_text(misfit, tests);
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
  io::write_text_atomic(ss_.folder + "/diagnosis.md", md_.str() + (prediction.empty() ? "" : "\n" + prediction));
  io::write_text_atomic(ss_.folder + "/models.csv", csv_.str());
}

}  // namespace dem
