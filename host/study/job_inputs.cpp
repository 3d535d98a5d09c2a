/// A calibration's or diagnosis's inputs (calibration_session.hpp, JobInputs): the data, the reference values, the
/// free parameters and the noise read and checked, the folders checked before any work, and the plan announced.
#include "host/study/calibration_session.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "host/fit/two_fidelity.hpp"
#include "host/util/progress.hpp"
#include "host/util/ranks.hpp"
#include "host/util/text_format.hpp"

namespace dem {

namespace fs = std::filesystem;

namespace {

/// The folders a job writes checked before any work (a refusal after the packings wasted them): the resumed folder
/// is one of this kind's, or -o names a folder (or none yet) whose nearest existing parent can be written.
void check_folders(const CalibrationOptions& o, const std::string& kind) {
  if (!o.resume.empty()) {
    resumed_folder(o.resume, kind);
    return;
  }
  if (o.output.empty()) throw std::invalid_argument("-o: an empty folder name (allowed: a folder to write in)");
  std::error_code ec;
  fs::path p = fs::absolute(o.output, ec);
  while (!p.empty() && !fs::exists(p, ec) && p != p.parent_path()) p = p.parent_path();
  if (!fs::is_directory(p, ec))
    throw std::invalid_argument("-o " + o.output + ": " + p.string() + " is a file, not a folder (allowed: a folder "
                                "to write in)");
  if (::access(p.c_str(), W_OK) != 0)
    throw std::invalid_argument("-o " + o.output + ": " + p.string() + " cannot be written (allowed: a folder to write in)");
  // Some folders pass access() and still refuse a new folder (/proc, as root): made once here, and what was made
  // removed again, so that a plan leaves nothing behind and a job learns it before any work. Only the leader
  // writes: shadows making and removing the same folder at once refused each other's (check_shared_folder later
  // tells whether every rank sees the leader's folder).
  const fs::path want = fs::absolute(o.output, ec);
  if (!ranks::leader() || fs::exists(want, ec)) return;
  if (!fs::create_directories(want, ec) || ec)
    throw std::invalid_argument("-o " + o.output + ": a folder cannot be made there (" + ec.message() +
                                "; allowed: a folder to write in)");
  for (fs::path q = want; q != p && !q.empty(); q = q.parent_path()) fs::remove(q, ec);
}

/// The free parameters: from the command line, else from the config's [calibrate] free.
std::vector<FreeParam> free_params(const Config& cfg, const std::vector<std::string>& cli) {
  std::vector<FreeParam> out;
  for (const std::string& n : cli.empty() ? cfg.calibrate.free : cli) {
    // A parameter twice would be two coordinates of one value: a singular fit.
    for (const FreeParam& f : out)
      if (f.name == n)
        throw ConfigError((cli.empty() ? cfg.path + ": [calibrate] free" : std::string("--free")) + ": " + n +
                          " given twice (each free parameter once)");
    try {
      out.push_back(free_param(n, model_of(cfg)));
    } catch (const std::invalid_argument& e) {
      if (!cli.empty()) throw;
      throw ConfigError(cfg.path + ": [calibrate] free: " + e.what());
    }
  }
  return out;
}

/// The data's noise as --noise names it: "data", "lab", or a lab noise file. Read before any simulator runs, so
/// that a bad file is refused at once.
NoiseOptions noise_options(const std::string& name) {
  if (name != "data" && name != "lab") return lab_noise_options(name);
  NoiseOptions n;
  n.mode = name;
  return n;
}

/// --predict walls, checked: the reference test must not be the walled cell already.
bool walls_prediction_wanted(const Config& base, const CalibrationOptions& o, const Config& cell) {
  if (!predicts_walls(base, o.predict)) return false;
  if (cell.periodic.boundary == CellBoundary::walls)
    throw ConfigError((o.predict.empty() ? base.path + ": [calibrate] predict" : std::string("--predict")) +
                      ": walls: the reference test is the cell between six walls already; predict a membrane test "
                      "(a config of configs/small/) or none");
  return true;
}

/// The q the reference cell's tests carry: the walled cell's walls measure the deviator force over the cross-section
/// at the start of shear and over the current one, and give the one the data name; the periodic cell gives its
/// contacts' stress (area_corrected), whatever the data name (two fidelities take the measure up in the membrane test).
QMeasure reference_q_measure(const Config& cell, const MeasuredData& data) {
  if (cell.periodic.boundary != CellBoundary::walls) return QMeasure::kAreaCorrected;
  if (data.q_measure != QMeasure::kFixedArea && data.q_measure != QMeasure::kAreaCorrected)
    throw DataError(data.path, "q_measure",
                    std::string("'") + name_of(data.q_measure) + "' is not a q the cell between walls measures "
                    "(allowed with the walled cell: fixed_area, the deviator force over the cross-section at the start "
                    "of shear, or area_corrected, over the current cross-section)");
  return data.q_measure;
}

/// --compression's tests, checked: each of a material the triaxial data hold, and a search that can fit them (the
/// ensemble's: two fidelities correct the triaxial misfit alone, one specimen a point whitens a run of one specimen).
/// Only a calibration searches as two fidelities or the config's [calibrate] method say (`calibrating`); a diagnosis
/// fits the periodic cell with the ensemble whatever the config says.
std::vector<CompressionTest> compression_tests(const Config& base, const CalibrationOptions& o,
                                               const MeasuredData& data, bool two_fidelity, bool calibrating) {
  if (o.compression.empty()) return {};
  std::vector<CompressionTest> tests = load_compression(o.compression);
  for (const CompressionTest& t : tests)
    if (std::none_of(data.tests.begin(), data.tests.end(), [&](const TriaxialTest& x) { return x.material == t.material; }))
      throw DataError(o.compression, "material", "'" + t.material + "' has no triaxial tests in " + o.data +
                                                     " (allowed: a material of the triaxial data, fitted with them)");
  if (calibrating && two_fidelity)
    throw ConfigError("--compression: two fidelities correct the triaxial misfit by the membrane test, which has no "
                      "compression test (allowed: --reference-test periodic)");
  if (calibrating && base.calibrate.one_specimen())
    throw ConfigError(base.path + ": [calibrate] method: \"" + base.calibrate.method + "\" with --compression "
                      "(allowed: \"ensemble\", whose every point is its members' mean, as the compression misfit compares)");
  return tests;
}

}  // namespace

Config stored_cell(const Config& cell, const CalibrationOptions& o, const MeasuredData& data) {
  Config c = sheared_for(cell, data);
  c.packing_store = (o.resume.empty() ? o.output : resumed_parent(o.resume)) + "/.specimens/cells";
  return c;
}

Config sheared_for(Config cell, const MeasuredData& data) {
  if (!data.curves) return cell;
  Real last = 0;
  for (const TriaxialTest& t : data.tests)
    if (!t.eps_a.empty()) last = std::max(last, t.eps_a.back());
  if (last > 0) cell.periodic.triax.target_strain = std::min(cell.periodic.triax.target_strain, kStrainBeyondData * last);
  return cell;
}

/// The tests of the data by material (sorted by name), filtered by `only` when it is set.
std::map<std::string, std::vector<TriaxialTest>> by_material(const MeasuredData& d, const std::string& only) {
  std::map<std::string, std::vector<TriaxialTest>> out;
  for (const TriaxialTest& t : d.tests)
    if (only.empty() || t.material == only) out[t.material].push_back(t);
  if (out.empty()) throw DataError(d.path + ": no tests of material '" + only + "'");
  return out;
}

JobInputs::JobInputs(const Config& base, const CalibrationOptions& o, const std::string& kind)
    : data(load_measured(o.data)),
      cell(reference_cell(base, o.reference_test)),
      ref(o.reference.empty() ? ReferenceValues{}
                              : load_reference(o.reference, [](const std::string& n) { free_param(n); })),
      free(free_params(base, o.free)), noise(noise_options(o.noise)), predict_template(prediction_template(base, o.predict)),
      walls_prediction(walls_prediction_wanted(base, o, cell)), workers(o.workers),
      two_fidelity(two_fidelity_wanted(base, o.reference_test, predict_template.has_value())),
      cell_q(reference_q_measure(cell, data)) {
  check_specimen_sizes(base, cell, data);
  take_walled_size(cell, data);
  if (two_fidelity) {
    const std::string key = o.predict.empty() ? base.path + ": [calibrate] predict" : "--predict";
    check_template_size(*predict_template, data.tests, key);
    check_template_law(base, *predict_template, key);
  }
  held_out = hold_out(o, data);
  check_enough_data(o, data, free.size());
  compression = compression_tests(base, o, data, two_fidelity, kind == "calibrate");
}

std::vector<CompressionTest> JobInputs::compression_of(const std::string& material) const {
  std::vector<CompressionTest> out;
  for (const CompressionTest& t : compression)
    if (t.material == material) out.push_back(t);
  return out;
}

JobPlan JobInputs::announce_plan(const Config& base, const CalibrationOptions& o, const std::string& kind) const {
  check_folders(o, kind);
  check_resumed_inputs(base, o, kind);
  PlanInput in;
  in.cell = stored_cell(cell, o, data);
  in.materials = by_material(data, o.material);
  in.state_tests = data.tests;
  for (const FreeParam& f : free) in.free.push_back(f.name);
  in.diagnose = kind == "diagnose";
  in.two_fidelity = two_fidelity;
  in.membrane = predict_template ? &*predict_template : nullptr;
  in.walls = walls_prediction;
  in.at_once = runs_at_once(o.workers);
  in.held_out = held_out;
  in.compression = compression;
  if (kind == "calibrate")
    for (const auto& m : in.materials)
      if (runs_reference(m.first)) in.reference_runs.push_back(m.first);
  JobPlan plan = plan_job(in);
  for (const std::string& n : data.notes) std::printf("%s: note: %s\n", kind.c_str(), n.c_str());
  std::printf("%s", plan.text(kind).c_str());
  const bool above_bound = plan.high() > kPlanBoundSeconds, above_ceiling = plan.high() > kPlanCeilingSeconds;
  if ((above_ceiling || (above_bound && !o.yes)) && !o.plan_only) {
    // The cause a user can change: the costliest stage's work and a run's length, beside the setting that sizes it.
    const PlanStage& top = plan.costliest();
    std::string run_steps;
    for (const std::string& n : plan.notes)
      if (n.rfind("a run of ", 0) == 0) run_steps = "; " + n.substr(0, n.find(','));
    const std::string cause = "its costliest stage is " + top.name + " (up to " + format_duration(top.high) + ": " +
                              top.work + run_steps + "), sized by " + top.setting +
                              " (docs/calibration.md, What a job costs)";
    if (above_ceiling)
      throw ConfigError(kind + ": the plan takes up to " + format_duration(plan.high()) + " on this machine, more than " +
                        format_duration(kPlanCeilingSeconds) + ", beyond what --yes starts: make it smaller, or spread "
                        "it over ranks (docs/cluster.md); " + cause);
    throw ConfigError(kind + ": the plan takes up to " + format_duration(plan.high()) + " on this machine, above the " +
                      format_duration(kPlanBoundSeconds) + " a job runs without asking: run it with --yes, or make it "
                      "smaller; " + cause);
  }
  return plan;
}

std::vector<Real> JobInputs::reference_point(const std::string& material) const {
  std::vector<Real> v;
  const auto m = ref.values.find(material);
  for (const FreeParam& f : free) {
    const bool given = m != ref.values.end() && m->second.count(f.name) > 0;
    v.push_back(given ? m->second.at(f.name) : std::nan(""));
  }
  return v;
}

bool JobInputs::runs_reference(const std::string& material) const {
  const std::vector<Real> v = reference_point(material);
  return !two_fidelity && std::all_of(v.begin(), v.end(), [](Real x) { return std::isfinite(x); });
}

}  // namespace dem
