#include "calibration_jobs.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <map>
#include <sstream>

#include "calibrate.hpp"
#include "host/io_hdf5.hpp"
#include "diagnose.hpp"
#include "progress.hpp"
#include "study.hpp"

namespace dem {

namespace fs = std::filesystem;

std::string new_dated_folder(const std::string& parent, const std::string& prefix) {
  const std::time_t now = std::time(nullptr);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", std::localtime(&now));
  fs::create_directories(parent);
  const std::string stem = (fs::path(parent) / (prefix + "_" + stamp)).string();
  for (int k = 1;; ++k) {
    const std::string path = k == 1 ? stem : stem + "-" + std::to_string(k);
    if (fs::create_directory(path)) return path;  // false: it exists; never reuse it
  }
}

namespace {

/// The free parameters: from the command line, else from the config's [calibrate] free.
std::vector<FreeParam> free_params(const Config& cfg, const std::vector<std::string>& cli) {
  std::vector<FreeParam> out;
  for (const std::string& n : cli.empty() ? cfg.calibrate.free : cli) {
    try {
      out.push_back(free_param(n, model_of(cfg)));
    } catch (const std::invalid_argument& e) {
      if (!cli.empty()) throw;
      throw ConfigError(cfg.path + ": [calibrate] free: " + e.what());
    }
  }
  return out;
}

/// The tests of the data by material (sorted by name), filtered by `only` when it is set.
std::map<std::string, std::vector<MeasuredTest>> by_material(const MeasuredData& d, const std::string& only) {
  std::map<std::string, std::vector<MeasuredTest>> out;
  for (const MeasuredTest& t : d.tests)
    if (only.empty() || t.material == only) out[t.material].push_back(t);
  if (out.empty()) throw DataError(d.path + ": no tests of material '" + only + "'");
  return out;
}

std::string fmt(const char* f, double v) {
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}

/// A quantity in the unit of the tables: MPa for the stiffness, kPa for stresses, % for the strain.
std::pair<double, const char*> in_table_unit(int q, Real v) {
  if (q == kInitialStiffness) return {1e-6 * v, "MPa"};
  if (q == kStrainAtPeak) return {100 * v, "pct"};
  if (q == kDilatancy) return {v, "-"};
  return {1e-3 * v, "kPa"};
}

/// The errors table (like the paper's Table 6): measured, simulated and error per test and quantity.
std::string errors_csv(const std::vector<MeasuredTest>& meas, const std::vector<MeasuredTest>& sim) {
  std::ostringstream s;
  s << "material,sigma3_kPa,quantity,unit,measured,simulated,error_pct\n";
  for (std::size_t k = 0; k < meas.size(); ++k) {
    const auto m = quantities(meas[k]), q = quantities(sim[k]);
    for (int i = 0; i < kQuantities; ++i) {
      if (!std::isfinite(m[i])) continue;
      s << meas[k].material << "," << fmt("%g", 1e-3 * meas[k].sigma3) << "," << quantity_name(i) << ","
        << in_table_unit(i, m[i]).second << "," << fmt("%.5g", in_table_unit(i, m[i]).first) << ","
        << fmt("%.5g", in_table_unit(i, q[i]).first) << ","
        << fmt("%.2f", 100 * (q[i] - m[i]) / std::fabs(m[i])) << "\n";
    }
  }
  return s.str();
}

void print_errors(const std::vector<MeasuredTest>& meas, const std::vector<MeasuredTest>& sim) {
  std::printf("%-10s %7s %-14s %12s %12s %8s\n", "material", "s3 kPa", "quantity", "measured", "simulated", "err %");
  std::istringstream in(errors_csv(meas, sim));
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    std::vector<std::string> c;
    std::stringstream ls(line);
    for (std::string x; std::getline(ls, x, ',');) c.push_back(x);
    std::printf("%-10s %7s %-14s %12s %12s %8s\n", c[0].c_str(), c[1].c_str(), (c[2] + " " + c[3]).c_str(),
                c[4].c_str(), c[5].c_str(), c[6].c_str());
  }
}

/// What calibrate and diagnose share: the data, the free parameters, the simulator and a new result folder.
struct Session {
  MeasuredData data;
  ReferenceValues ref;
  std::vector<FreeParam> free;
  StateMatch state;  ///< the data's void ratio and the preparation that packs it
  PeriodicLab lab;
  std::string folder;
  Session(const Config& base, const CalibrationOptions& o, const std::string& kind)
      : data(load_measured(o.data)),
        ref(o.reference.empty() ? ReferenceValues{}
                                : load_reference(o.reference, [](const std::string& n) { free_param(n); })),
        free(free_params(base, o.free)), lab(matched(base), true), folder(new_dated_folder(o.output, kind)) {
    lab.set_jobs(o.jobs);
    noise.mode = o.noise;
    for (const std::string& n : data.notes) std::printf("%s: note: %s\n", kind.c_str(), n.c_str());
  }
  NoiseOptions noise;
  Config matched(const Config& base) { return matched_state(base, data.tests, state, true); }
  /// The report's line on the specimens' state.
  std::string state_text(const Misfit& m, const std::vector<MeasuredTest>& tests) const {
    if (state.tests == 0)
      return "The data give no void ratio: the simulator's specimens have the density their preparation gives (" +
             fmt("e = %.3f", lab.prepared_void_ratio(0)) + " for the first), and the calibrated friction absorbs "
             "any difference in density.\n";
    std::string s = "The simulator's specimens were prepared to the data's void ratio " + fmt("%.4f", state.target) +
                    " (preparation friction " + fmt("%.4g", state.prep_mu_s) + ", which packs " +
                    fmt("%.4f", state.reached) +
                    "). At the start of shear, measured and simulated (mean of the scatter specimens at the base "
                    "model):";
    for (std::size_t k = 0; k < tests.size(); ++k)
      s += fmt(" %g kPa", 1e-3 * tests[k].sigma3) + fmt(" %.4f", tests[k].void_ratio) +
           fmt(" against %.4f;", m.reached_void_ratio(k));
    return s + "\n";
  }
  /// The misfit of a material's tests: the ensemble run at the base model, its scatter beside the data's noise.
  Misfit misfit_of(const Config& base, const std::string& material, const std::vector<MeasuredTest>& tests) {
    std::printf("%s: %s: measuring the simulator's scatter: %d specimens of %zu balls at the base model\n",
                folder.c_str(), material.c_str(), lab.members(), lab.balls());
    Misfit m = measure_misfit(lab, model_of(base), tests, noise);
    for (const std::string& n : m.notes()) std::printf("  noise: %s\n", n.c_str());
    const Real ratio = m.ensemble_ratio();
    std::printf("  the simulator's standard error is %.2f of the data's noise (median; %d specimens)%s\n", ratio,
                lab.members(), ratio > 0.5 ? "" : ": below 1/2, enough");
    if (ratio > 0.5)
      std::printf("  WARNING: above 1/2: [calibrate] ensemble = %ld would bring it to 1/2; the misfit counts it\n",
                  std::lround(std::ceil(lab.members() * 4 * ratio * ratio)));
    return m;
  }
  /// The reference value of a parameter for a material, in the key's unit; NaN when there is none.
  Real reference(const std::string& material, const std::string& name) const {
    auto m = ref.values.find(material);
    if (m == ref.values.end()) return std::nan("");
    auto v = m->second.find(name);
    return v == m->second.end() ? std::nan("") : v->second;
  }
  /// The errors table, the curves in the measured-data format and the figure.
  void finish(const std::vector<MeasuredTest>& meas, const std::vector<MeasuredTest>& sim,
              const std::string& what) const {
    io::write_text_atomic(folder + "/errors.csv", errors_csv(meas, sim));
    write_measured_curves(folder + "/simulated_curves.csv", sim, "simulated by " + what);
    if (data.curves) write_measured_curves(folder + "/measured_curves.csv", meas, "measured: " + data.path);
    run_plot_script("plot_calibration.py", {folder});
  }
};

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
  if (r.scale > 1)
    o << at << "the misfit exceeds the noise (chi2 / dof " << fmt("%.2f", r.scale)
      << "): the intervals are widened by its square root\n";
  o << at << r.design.size() << " parameter points run to find the optimum\n";
  return o.str();
}

/// A feature's value and unit in the tables: q in kPa, eps_v in %, summary quantities in_table_unit.
std::pair<double, const char*> feature_unit(const Feature& f, Real v) {
  if (f.strain == 0) return in_table_unit(f.quantity, v);
  return f.quantity == 0 ? std::make_pair(1e-3 * v, "kPa") : std::make_pair(100 * v, "pct");
}

/// The noise used, per test and quantity: the median over the test's features of each part.
std::string noise_table(const Misfit& mf, const std::vector<MeasuredTest>& tests) {
  std::ostringstream md;
  md << "Noise (" << mf.source() << "; median standard deviation over each test's data; the simulator's is that of "
     << "the mean of " << mf.members() << " specimens; correlation length along strain "
     << fmt("%.2f", mf.correlation_length()) << " in ln strain):\n\n| sigma3 kPa | quantity | data | measured specimen | "
        "simulator mean |\n|---|---|---|---|---|\n";
  for (std::size_t k = 0; k < mf.tests(); ++k) {
    std::map<std::string, std::vector<std::array<Real, 3>>> by;
    for (const Feature& f : mf.features(k)) {
      const std::string q = f.strain > 0 ? (f.quantity == 0 ? "q (kPa)" : "eps_v (%)") : f.name;
      const Real u = feature_unit(f, 1).first;
      by[q].push_back({u * f.data_sd, u * f.specimen_sd, u * f.ensemble_sd / std::sqrt(Real(mf.members()))});
    }
    for (auto& [q, v] : by) {
      md << "| " << fmt("%g", 1e-3 * tests[k].sigma3) << " | " << q;
      for (int c = 0; c < 3; ++c) {
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
std::string gain_tables(const Misfit& mf, const std::vector<MeasuredTest>& tests, const Evaluation& base,
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
      const Real s = std::sqrt(f.data_sd * f.data_sd + f.specimen_sd * f.specimen_sd +
                               f.ensemble_sd * f.ensemble_sd / mf.members());
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

}  // namespace

int calibrate_job(const Config& base, const CalibrationOptions& o) {
  Session ss(base, o, "calibrate");
  std::ostringstream table;
  table << "material,parameter,value,low95,high95,reference,chi2,data,runs\n";
  std::vector<MeasuredTest> all_meas, all_sim;
  for (const auto& [material, tests] : by_material(ss.data, o.material)) {
    std::printf("calibrate: %s, %zu tests, free %zu parameters, %zu balls in the periodic cell\n", material.c_str(),
                tests.size(), ss.free.size(), ss.lab.balls());
    const long planned = (std::lround(std::pow(3.0, ss.free.size())) + 4) * static_cast<long>(tests.size()) *
                         ss.lab.members();
    Progress progress("calibrate " + material, planned);
    const long runs0 = ss.lab.runs();
    const Misfit misfit = ss.misfit_of(base, material, tests);
    const CalibrationResult r = calibrate(ss.lab, model_of(base), ss.free, tests, misfit, 4,
                                          [&](long done, long, Real chi2) {
                                            char extra[64];
                                            std::snprintf(extra, sizeof extra, "runs, best chi2 %.1f", chi2);
                                            progress.update(std::min(done - runs0, planned), extra);
                                          });
    progress.finish("");
    for (std::size_t k = 0; k < ss.free.size(); ++k) {
      const FreeParam& f = ss.free[k];
      const Real ref = ss.reference(material, f.name);
      std::printf("calibrate: %s: %s = %.4g%s\n", material.c_str(), f.name.c_str(), f.shown * r.values[k],
                  std::isfinite(ref) ? fmt(" (reference %g)", ref).c_str() : "");
      table << material << "," << f.name << "," << fmt("%.6g", f.shown * r.values[k]) << ","
            << fmt("%.6g", f.shown * r.interval[k].first) << "," << fmt("%.6g", f.shown * r.interval[k].second) << ","
            << (std::isfinite(ref) ? fmt("%g", ref) : "") << "," << fmt("%.3f", r.best.chi2) << "," << r.data << "," << ss.lab.runs() - runs0 << "\n";
    }
    std::printf("%s", uncertainty_text(r, material, "calibrate").c_str());
    for (const std::string& note : r.widened) std::printf("calibrate: %s: %s\n", material.c_str(), note.c_str());
    for (const std::string& name : r.at_edge())
      std::printf("calibrate: %s: WARNING: %s is at the edge of its range: widen it (the optimum may lie "
                  "outside)\n", material.c_str(), name.c_str());
    std::printf("calibrate: %s: chi2 %.1f on %d data after %ld runs\n", material.c_str(), r.best.chi2, r.data,
                ss.lab.runs() - runs0);
    all_meas.insert(all_meas.end(), tests.begin(), tests.end());
    all_sim.insert(all_sim.end(), r.best.sim.begin(), r.best.sim.end());
  }
  print_errors(all_meas, all_sim);
  io::write_text_atomic(ss.folder + "/calibrated.csv", table.str());
  std::printf("calibrate: %ld runs in %s; results in %s (calibrated.csv, errors.csv, simulated_curves.csv)\n",
              ss.lab.runs(), format_duration(ss.lab.seconds()).c_str(), ss.folder.c_str());
  ss.finish(all_meas, all_sim, "the calibrated parameters");
  return 0;
}

int diagnose_job(const Config& base, const CalibrationOptions& o) {
  Session ss(base, o, "diagnose");
  std::ostringstream md, csv;
  md << "# Diagnosis of " << o.data << "\n\n"
     << "Simulator: periodic-cell triaxial, an ensemble of " << ss.lab.members() << " specimens of " << ss.lab.balls()
     << " balls (packing seeds from " << base.run.seed << "), each prepared once; every parameter point runs them all "
        "and compares their mean. Free base parameters:";
  for (const FreeParam& f : ss.free) md << " " << f.name;
  md << ". Misfit: chi2 over " << (ss.data.curves ? "q and eps_v at fixed axial strains (0.02% to 15%)"
                                                  : "the summary quantities given")
     << ", with the data's noise, the measured specimen's own scatter and the simulator's standard error "
        "(host/misfit.hpp); noise: " << ss.noise.mode << ".\n\n";
  if (!ss.ref.values.empty())
    md << "Reference values: " << ss.ref.path << (ss.ref.comment.empty() ? "" : ": " + ss.ref.comment)
       << " The calibrated values belong to this simulator (its cell, density and boundary), the reference values to "
          "the model they were calibrated with: a difference between them measures the two simulators as much as "
          "the data.\n\n";
  for (const std::string& n : ss.data.notes) md << "Note on the data: " << n << "\n\n";
  csv << "material,model,parameter,value,chi2,bic,heldout_chi2,runs\n";
  std::vector<MeasuredTest> all_meas, all_sim, all_ext;
  for (const auto& [material, tests] : by_material(ss.data, o.material)) {
    const Misfit misfit = ss.misfit_of(base, material, tests);
    const Diagnosis dg = diagnose(ss.lab, model_of(base), ss.free, tests, misfit, true);
    std::printf("diagnose: %s: verdict: %s\n  %s\n", material.c_str(), dg.verdict.c_str(), dg.explanation.c_str());
    std::printf("%s", uncertainty_text(dg.base, material, "diagnose").c_str());
    std::string edge, widened;
    for (const std::string& note : dg.base.widened) {
      std::printf("diagnose: %s: %s\n", material.c_str(), note.c_str());
      widened += (widened.empty() ? "" : "; ") + note;
    }
    for (const std::string& name : dg.base.at_edge()) edge += (edge.empty() ? "" : ", ") + name;
    if (!edge.empty())
      std::printf("diagnose: %s: WARNING: %s at the edge of the search range\n", material.c_str(), edge.c_str());
    md << "## " << material << "\n\n**Verdict: " << dg.verdict << ".** " << dg.explanation << "\n\n"
       << noise_table(misfit, tests)
       << (widened.empty() ? "" : "Search ranges: " + widened + ".\n\n")
       << (edge.empty() ? "" : "**Warning:** the base model's " + edge + " lies at the edge of its search range: the "
                               "optimum may lie outside, and part of the misfit may be the range's, not the model's.\n\n")
       << "| model | parameters | chi2 | BIC | held-out chi2 | runs |\n|---|---|---|---|---|---|\n| base | ";
    for (std::size_t k = 0; k < ss.free.size(); ++k) {
      md << ss.free[k].name << " = " << fmt("%.4g", ss.free[k].shown * dg.base.values[k]) << " ";
      csv << material << ",base," << ss.free[k].name << "," << fmt("%.6g", ss.free[k].shown * dg.base.values[k]) << ","
          << fmt("%.3f", dg.base.best.chi2) << "," << fmt("%.3f", dg.base_bic) << "," << fmt("%.3f", dg.base_heldout)
          << "," << dg.base.design.size() * tests.size() << "\n";
    }
    md << "| " << fmt("%.1f", dg.base.best.chi2) << " | " << fmt("%.1f", dg.base_bic) << " | "
       << fmt("%.1f", dg.base_heldout) << " | " << dg.base.design.size() * tests.size() * ss.lab.members() << " |\n";
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
    if (!ss.ref.values.empty()) {
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
    }
    md << "\nEach extension against the base model:\n\n";
    for (const ExtensionFit& f : dg.fits) md << "- **" << f.ext.name << "**: " << f.reason << "\n";
    for (const std::string& n : dg.notes) md << "- " << n << "\n";
    md << "\nThe base model's calibrated values:\n\n```\n" << uncertainty_text(dg.base, material, "diagnose")
       << "```\n";
    md << "\n" << ss.state_text(misfit, tests);
    const ExtensionFit* top = top_fit(dg);
    if (top) {
      md << gain_tables(misfit, tests, dg.base.best, top->best,
                        top->ext.name + (dg.verdict == "none" ? " (candidate, not named)" : ""));
      all_ext.insert(all_ext.end(), top->best.sim.begin(), top->best.sim.end());
      std::printf("diagnose: %s: gain of %s: chi2 %.1f -> %.1f, held-out chi2 %.1f -> %.1f (diagnosis.md has it by "
                  "pressure, strain range and quantity)\n", material.c_str(), top->ext.name.c_str(),
                  dg.base.best.chi2, top->best.chi2, dg.base_heldout, top->heldout);
    }
    md << "\n";
    all_meas.insert(all_meas.end(), tests.begin(), tests.end());
    all_sim.insert(all_sim.end(), dg.base.best.sim.begin(), dg.base.best.sim.end());
  }
  md << "![measured and simulated: the base model in full lines, the extended one dashed](calibration.png)\n";
  if (all_ext.size() == all_meas.size())
    write_measured_curves(ss.folder + "/extended_curves.csv", all_ext, "simulated by the extended model of each material");
  io::write_text_atomic(ss.folder + "/diagnosis.md", md.str());
  io::write_text_atomic(ss.folder + "/models.csv", csv.str());
  std::printf("diagnose: %ld runs in %s; report in %s/diagnosis.md\n", ss.lab.runs(),
              format_duration(ss.lab.seconds()).c_str(), ss.folder.c_str());
  ss.finish(all_meas, all_sim, "the calibrated base model");
  return 0;
}

int synth_job(const Config& base, const SynthOptions& o) {
  Model truth = model_of(base);
  std::string comment = "synthetic data from " + base.path + ", seed " + std::to_string(o.seed) + ", extension " +
                        o.extension;
  if (o.extension != "none") {
    const Extension& e = extension(o.extension);
    const Real v = o.strength >= 0 ? o.strength / free_param(e.param).shown  // given in the key's unit
                                   : draw_strength(e, o.seed);
    set_param(truth, e.param, v);
    comment += " (" + e.param + " = " + fmt("%.4g", free_param(e.param).shown * v) + ")";
  }
  const unsigned specimen = o.specimen_seed >= 0 ? static_cast<unsigned>(o.specimen_seed)
                                                 : base.run.seed + kForeignSeedOffset;
  comment += ", a specimen per test (packing seeds from " + std::to_string(specimen) + ", " +
             std::to_string(kGeneratorCellFactor) + " times the config's balls)";
  PeriodicLab lab(larger_cell(base, kGeneratorCellFactor), false, static_cast<int>(o.sigma3.size()), specimen);
  const std::vector<MeasuredTest> tests = synthetic_tests(lab, truth, o.sigma3, o.material, o.seed);
  write_measured_curves(o.output, tests, comment);
  std::printf("synth: %s -> %s\n", comment.c_str(), o.output.c_str());
  return 0;
}

}  // namespace dem
