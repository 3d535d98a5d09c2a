#include "host/study/calibration_jobs.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <map>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "host/study/calibration_session.hpp"
#include "host/study/diagnosis_report.hpp"
#include "host/data/curve_reading.hpp"
#include "host/fit/calibrate.hpp"
#include "host/fit/calibration_report.hpp"
#include "host/fit/compression_misfit.hpp"
#include "host/fit/diagnose.hpp"
#include "host/fit/prediction.hpp"
#include "host/fit/two_fidelity.hpp"
#include "host/io/io_hdf5.hpp"
#include "host/triax/summary.hpp"
#include "host/util/progress.hpp"
#include "host/util/ranks.hpp"
#include "host/util/text_format.hpp"

namespace dem {

namespace fs = std::filesystem;

std::string new_dated_folder(const std::string& parent, const std::string& prefix) {
  if (!ranks::leader()) return ranks::agree("");  // the leader's folder: each rank's clock would name another
  const std::time_t now = std::time(nullptr);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", std::localtime(&now));
  fs::create_directories(parent);
  const std::string stem = (fs::path(parent) / (prefix + "_" + stamp)).string();
  for (int k = 1;; ++k) {
    const std::string path = k == 1 ? stem : stem + "-" + std::to_string(k);
    if (fs::create_directory(path)) return ranks::agree(path);  // false: it exists; never reuse it
  }
}

namespace {

/// A folder as a path without a trailing separator ("out/calibrate_x/" names calibrate_x).
fs::path folder_path(const std::string& folder) {
  fs::path p = fs::path(folder).lexically_normal();
  return p.has_filename() ? p : p.parent_path();
}

}  // namespace

std::string resumed_folder(const std::string& folder, const std::string& kind) {
  const std::string name = folder_path(folder).filename().string();
  if (!fs::is_directory(folder) || name.rfind(kind + "_", 0) != 0)
    throw std::invalid_argument("--resume " + folder + ": not a " + kind + "_<date> folder of an earlier " + kind +
                                " (it gives the folder to continue in)");
  return folder_path(folder).string();
}

std::string resumed_parent(const std::string& folder) {
  const fs::path parent = folder_path(folder).parent_path();
  return parent.empty() ? "." : parent.string();
}

namespace {

/// A search whose every point, or most of whose runs, blew up has no answer: stopped with the blow-ups named, not
/// reported as values.
void require_a_result(const CalibrationResult& r, const std::string& what, const Session& ss) {
  if (!std::isfinite(r.best.chi2))
    throw std::runtime_error(what + ": no point of the search gave a result (" + ss.failed_text() + ")");
  if (ss.lab.mostly_failed())
    throw std::runtime_error(what + ": " + std::to_string(ss.lab.failed_runs()) + " of " +
                             std::to_string(ss.lab.runs()) + " runs stopped at a blow-up, more than half: no result "
                             "is given on the few that ended (" + ss.failed_text() + ")");
}

/// Two fidelities from the periodic optimum `r`: the membrane test's discrepancy at each optimum and the cell
/// calibrated to the data less it (`fit(misfit, what)`), to a fixed point; the rounds in stdout and the report.
template <class Fit>
CalibrationResult two_fidelity_fit(Session& ss, const Config& base, const std::string& material,
                                   const std::vector<TriaxialTest>& tests, const Misfit& misfit,
                                   const CalibrationResult& r, const Fit& fit) {
  int round = 0;
  const FidelityRounds rounds = two_fidelity_rounds(r, misfit, tests, [&](const Model& at) {
    std::string where;
    for (const FreeParam& f : ss.in.free)
      where += (where.empty() ? " " : ", ") + f.name + fmt(" = %.4g", f.shown * get_param(at, f.name));
    std::printf("calibrate: %s: two fidelities, membrane test %d: it and every periodic specimen at%s\n",
                material.c_str(), ++round, where.c_str());
    const Discrepancy d = measure_discrepancy(misfit, ss.predict_at(base, at, tests),
                                              ss.lab.run_ensemble(at, tests, true));
    std::printf("%s", discrepancy_text(misfit, d, tests).c_str());
    return d;
  }, [&](const Misfit& corrected) {
    return fit(corrected, "calibrate (corrected, round " + std::to_string(round) + ")");
  }, ss.in.predict_template->path, kFidelityRounds, [&](const Model& at, const Misfit& corrected) {
    const Ensemble e = ss.lab.run_ensemble(at, tests, true);
    Evaluation ev;
    for (const std::vector<TriaxialTest>& members : e) ev.sim.push_back(mean_curve(members));
    ev.r = corrected.residuals(e);
    for (Real x : ev.r) ev.chi2 += x * x;
    return ev;
  });
  const std::string text = rounds.text();
  std::printf("calibrate: %s: two fidelities:\n%s", material.c_str(), text.c_str());
  ss.report.discrepancy += "### " + material + "\n\n" + text + "\n";
  return rounds.last();
}

/// The misfit of the material's compression tests (--compression), their scatter run at the base on every scatter
/// specimen; none without such tests. `kind`: the job, for its lines.
std::optional<CompressionMisfit> compression_misfit(Session& ss, const Config& base, const std::string& material,
                                                    const std::string& kind) {
  const std::vector<CompressionTest> tests = ss.in.compression_of(material);
  if (tests.empty()) return std::nullopt;
  const long start = ss.lab.runs();
  Progress progress(kind + " " + material + ": the compression tests' scatter at the base",
                    static_cast<long>(tests.size()) * ss.lab.specimens());
  CompressionMisfit m(tests, ss.lab.run_compressions(model_of(base), tests, true), ss.lab.members());
  progress.finish(std::to_string(ss.lab.runs() - start) + " runs");
  std::printf("%s: %s: %zu compression test%s fitted with the triaxial ones: %d data (strain increments%s)\n",
              kind.c_str(), material.c_str(), tests.size(), tests.size() == 1 ? "" : "s", m.data(),
              std::any_of(tests.begin(), tests.end(), [](const CompressionTest& t) { return !t.k0.empty(); })
                  ? " and K0" : "");
  return m;
}

/// What a job does with each material's tests: the calibration's fit, or the diagnosis. The loop over the
/// materials, the account of the runs, the prediction and the pools are the job's (run_materials), one for both.
class MaterialWork {
 public:
  virtual ~MaterialWork() = default;
  /// Fits `tests` of `material` against `misfit`: the calibrated model and its curves, for the prediction.
  virtual Calibrated fit(const std::string& material, const std::vector<TriaxialTest>& tests,
                         const Misfit& misfit) = 0;
  /// After every material: the job's lines and files; returns where its results are, for the closing line.
  virtual std::string close(const std::vector<TriaxialTest>& meas, const std::vector<TriaxialTest>& sim) = 0;
  /// The prediction's text (not empty), once the membrane tests or the walled runs have ended.
  virtual void predicted(const std::string& prediction) = 0;
  /// What the curves of fit are, in the job's closing lines.
  virtual const char* fitted() const = 0;
};

int run_materials(const Config& base, const CalibrationOptions& o, Session& ss, const std::string& kind,
                  MaterialWork& work) {
  std::vector<TriaxialTest> all_meas, all_sim;
  std::map<std::string, Calibrated> models;
  for (const auto& [material, tests] : by_material(ss.in.data, o.material)) {
    std::printf("%s: %s, %zu tests, free %zu parameters, %zu balls in %s\n", kind.c_str(), material.c_str(),
                tests.size(), ss.in.free.size(), ss.lab.balls(), ss.cell_text().c_str());
    const Misfit misfit = ss.misfit_of(base, material, tests);  // sets the ensemble ("auto": from the scatter)
    Calibrated c = work.fit(material, tests, misfit);
    all_meas.insert(all_meas.end(), tests.begin(), tests.end());
    all_sim.insert(all_sim.end(), c.sim.begin(), c.sim.end());
    models[material] = std::move(c);
  }
  const std::string where = work.close(all_meas, all_sim);
  std::printf("%s: %s in %s; %s\n", kind.c_str(), ss.runs_text().c_str(), format_duration(ss.lab.seconds()).c_str(),
              where.c_str());
  // A line of its own: inside the runs' line the job's time read as part of the fix ("raise overlap_limit in 11m48s").
  if (ss.lab.failed_runs() > 0) std::printf("%s: WARNING: %s\n", kind.c_str(), ss.failed_text().c_str());
  if (const std::string w = ss.report.workers_text(); !w.empty()) std::printf("%s: %s\n", kind.c_str(), w.c_str());
  ss.report.finish(ss.in.data, all_meas, all_sim, work.fitted());
  const std::string prediction = ss.predict_boundary(base, models);
  if (!prediction.empty()) work.predicted(prediction);
  ss.report.write_pools();
  std::printf("%s: %s\n", kind.c_str(), ss.report.plan_text().c_str());
  return 0;
}

/// The calibration of each material: the fit (two fidelities where asked), the scatter at the answer, the reference
/// placed, the values with their intervals in calibrated.csv.
class CalibrationWork : public MaterialWork {
 public:
  CalibrationWork(Session& ss, const Config& base)
      : ss_(ss), base_(base), one_specimen_(base.calibrate.one_specimen()) {
    table_ << "material,parameter,value,low95,high95,reference,chi2,data,runs,reference_rise,reference_chi2\n";
  }

  Calibrated fit(const std::string& material, const std::vector<TriaxialTest>& tests, const Misfit& misfit) override {
    Session& ss = ss_;
    const long runs0 = ss.lab.runs();
    const std::optional<CompressionMisfit> compression = compression_misfit(ss, base_, material, "calibrate");
    const JointTerm joint = compression ? compression->joint(ss.lab) : JointTerm{};
    auto fit = [&](const Misfit& m, const std::string& what) {
      const long start = ss.lab.runs();
      const int d = static_cast<int>(ss.in.free.size());
      const long planned = static_cast<long>(tests.size()) *
                           (one_specimen_ ? planned_one_specimen_points(d) : planned_points(d) * ss.lab.members());
      Progress progress(what + " " + material, planned);
      const CalibrationProgress report = [&](long done, long, Real chi2) {
        char extra[64];
        std::snprintf(extra, sizeof extra, "runs, best chi2 %.1f", chi2);
        progress.update(done - start, extra);
      };
      CalibrationResult r = one_specimen_
                                ? calibrate_one_specimen(ss.lab, model_of(base_), ss.in.free, tests, m.with_members(1), report)
                                : calibrate(ss.lab, model_of(base_), ss.in.free, tests, m, 4, report, 2, joint);
      progress.finish("");
      require_a_result(r, what + " " + material, ss);
      return r;
    };
    CalibrationResult r = fit(misfit, "calibrate");
    if (ss.in.two_fidelity) r = two_fidelity_fit(ss, base_, material, tests, misfit, r, fit);
    // The noise at the answer: the scatter specimens run again at the calibrated point, and the design whitened by it
    // (rewhiten). Two fidelities fit a misfit corrected by the membrane test, which is measured at its own points.
    const Misfit there = ss.in.two_fidelity ? misfit : rescattered(ss, material, tests, misfit, r, model_of(base_));
    // A reference that gives every free parameter is placed against the joint region, and run (runs_reference): is
    // it consistent with these data?
    const long fit_runs = ss.lab.runs() - runs0;  // the reference point's runs are not the calibration's
    const auto [reference_rise, reference_chi2] = place_reference(ss, material, tests, there, r);
    const bool whole_reference = !std::isnan(reference_rise);  // inf: outside the searched ranges
    for (std::size_t k = 0; k < ss.in.free.size(); ++k) {
      const FreeParam& f = ss.in.free[k];
      const Real ref = ss.reference(material, f.name);
      std::printf("calibrate: %s: %s = %.4g%s\n", material.c_str(), f.name.c_str(), f.shown * r.values[k],
                  std::isfinite(ref) ? fmt(" (reference %g)", ref).c_str() : "");
      table_ << material << "," << f.name << "," << fmt("%.6g", f.shown * r.values[k]) << ","
             << fmt("%.6g", f.shown * r.interval[k].first) << "," << fmt("%.6g", f.shown * r.interval[k].second)
             << "," << (std::isfinite(ref) ? fmt("%g", ref) : "") << "," << fmt("%.3f", r.best.chi2) << ","
             << r.data << "," << fit_runs << "," << (whole_reference ? fmt("%.4g", reference_rise) : "") << ","
             << (std::isfinite(reference_chi2) ? fmt("%.3f", reference_chi2) : "") << "\n";
    }
    std::printf("%s", uncertainty_text(r, material, "calibrate").c_str());
    for (const std::string& note : r.widened) std::printf("calibrate: %s: %s\n", material.c_str(), note.c_str());
    for (const std::string& name : r.at_edge())
      std::printf("calibrate: %s: WARNING: %s is at the edge of its range: widen it (the optimum may lie "
                  "outside)\n", material.c_str(), name.c_str());
    std::printf("calibrate: %s: chi2 %.1f on %d data after %ld runs\n", material.c_str(), r.best.chi2, r.data,
                fit_runs);
    if (compression) compression_fit(material, *compression, r.model);
    std::vector<TriaxialTest> held;
    for (const TriaxialTest& t : ss.in.held_out)
      if (t.material == material) held.push_back(t);
    return Calibrated{tests, r.model, r.best.sim, held};
  }

  std::string close(const std::vector<TriaxialTest>& meas, const std::vector<TriaxialTest>& sim) override {
    if (ss_.in.two_fidelity)
      std::printf("calibrate: two fidelities: the table sets the periodic cell against the data as measured; it was "
                  "fitted to them less the boundary's discrepancy, and the membrane prediction below is the test "
                  "that compares with the lab\n");
    print_errors(meas, sim);
    io::write_text_atomic(ss_.report.folder + "/calibrated.csv", table_.str());
    return "results in " + ss_.report.folder + " (calibrated.csv, errors.csv, simulated_curves.csv)";
  }

  void predicted(const std::string& prediction) override {
    io::write_text_atomic(ss_.report.folder + "/prediction.md", prediction);
  }

  const char* fitted() const override { return "the calibrated parameters"; }

 private:
  Session& ss_;
  const Config& base_;
  bool one_specimen_;  ///< [calibrate] method "one_specimen"
  std::ostringstream table_;
  std::string compression_table_;  ///< compression_fit.csv: every material's compression tests at its answer

  /// The compression tests at the answer, printed and kept in compression_fit.csv.
  void compression_fit(const std::string& material, const CompressionMisfit& m, const Model& at) {
    const CompressionEnsemble sim = ss_.lab.run_compressions(at, m.measured());
    const std::vector<Real> r = m.residuals(sim);
    Real chi2 = 0;
    for (Real x : r) chi2 += x * x;
    const std::string table = m.table(sim);
    std::printf("calibrate: %s: the compression tests at the answer: chi2 %.1f on %d data\n%s", material.c_str(), chi2,
                m.data(), table.c_str());
    compression_table_ += compression_table_.empty() ? table : table.substr(table.find('\n') + 1);
    io::write_text_atomic(ss_.report.folder + "/compression_fit.csv", compression_table_);
  }
};

/// The diagnosis of each material: the base model's fit, each extension's, the verdict; diagnosis.md.
class DiagnosisWork : public MaterialWork {
 public:
  DiagnosisWork(Session& ss, const Config& base, const CalibrationOptions& o)
      : ss_(ss), base_(base), report_(ss, base, o) {
    if (base.calibrate.one_specimen())
      std::printf("diagnose: [calibrate] method \"%s\" is calibrate's: the diagnosis searches with the ensemble, "
                  "every extension's fit on the same specimens as the base's\n", base.calibrate.method.c_str());
  }

  Calibrated fit(const std::string& material, const std::vector<TriaxialTest>& tests, const Misfit& misfit) override {
    const std::optional<CompressionMisfit> compression = compression_misfit(ss_, base_, material, "diagnose");
    const Diagnosis dg = diagnose(ss_.lab, model_of(base_), ss_.in.free, tests, misfit, true,
                                  compression ? compression->joint(ss_.lab) : JointTerm{});
    require_a_result(dg.base, "diagnose " + material + " (the base model's search)", ss_);
    std::printf("diagnose: %s: verdict: %s\n  %s\n", material.c_str(), dg.verdict.c_str(), dg.explanation.c_str());
    std::printf("%s", uncertainty_text(dg.base, material, "diagnose").c_str());
    for (const std::string& note : dg.base.widened) std::printf("diagnose: %s: %s\n", material.c_str(), note.c_str());
    if (const std::string edge = edge_names(dg.base); !edge.empty())
      std::printf("diagnose: %s: WARNING: %s at the edge of the search range\n", material.c_str(), edge.c_str());
    if (const ExtensionFit* top = report_.add_material(material, tests, misfit, dg)) {
      extended_.insert(extended_.end(), top->best.sim.begin(), top->best.sim.end());
      std::printf("diagnose: %s: gain of %s: chi2 %.1f -> %.1f, held-out chi2 %.1f -> %.1f (diagnosis.md has it by "
                  "pressure, strain range and quantity)\n", material.c_str(), top->ext.name.c_str(),
                  dg.base.best.chi2, top->best.chi2, dg.base_heldout, top->heldout);
    }
    return Calibrated{tests, dg.base.model, dg.base.best.sim, {}};
  }

  std::string close(const std::vector<TriaxialTest>& meas, const std::vector<TriaxialTest>&) override {
    report_.close();
    if (extended_.size() == meas.size())
      write_measured_curves(ss_.report.folder + "/extended_curves.csv", extended_,
                            "simulated by the extended model of each material");
    report_.write();
    return "report in " + ss_.report.folder + "/diagnosis.md";
  }

  // The report stands before the membrane tests run; their section is added when they end.
  void predicted(const std::string& prediction) override { report_.write(prediction); }

  const char* fitted() const override { return "the calibrated base model"; }

 private:
  Session& ss_;
  const Config& base_;
  DiagnosisReport report_;
  std::vector<TriaxialTest> extended_;  ///< the best extension's curves, where a material has one
};

}  // namespace

int calibrate_job(const Config& base, const CalibrationOptions& o) {
  if (o.plan_only) return JobInputs(base, o, "calibrate").announce_plan(base, o, "calibrate"), 0;
  Session ss(base, o, "calibrate");
  CalibrationWork work(ss, base);
  return run_materials(base, o, ss, "calibrate", work);
}

int diagnose_job(const Config& base, const CalibrationOptions& o) {
  if (o.plan_only) return JobInputs(base, o, "diagnose").announce_plan(base, o, "diagnose"), 0;
  Session ss(base, o, "diagnose");
  if (ss.in.two_fidelity)
    std::printf("diagnose: note: the diagnosis fits the periodic cell; two fidelities apply to calibrate (the "
                "membrane prediction at the end shows what the boundary adds)\n");
  DiagnosisWork work(ss, base, o);
  return run_materials(base, o, ss, "diagnose", work);
}

}  // namespace dem
