#include "host/study/study.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "host/engine/checkpoint.hpp"
#include "host/io/io_hdf5.hpp"
#include "host/util/progress.hpp"

namespace dem {

namespace fs = std::filesystem;

double study_case_cost(const Config& cfg) {
  const double d = cfg.particles.diameter;
  const double ball = M_PI / 6 * d * d * d;
  if (cfg.has_periodic) {
    const PeriodicTriaxialParams& t = cfg.periodic.triax;
    return static_cast<double>(cfg.particles.count) * t.target_strain / (t.target_inertial * std::sqrt(t.sigma3));
  }
  const SpecimenConfig& s = cfg.specimen;
  const double balls = s.ball_count > 0 ? static_cast<double>(s.ball_count)
                                        : M_PI / 4 * s.diameter * s.diameter * s.height / (1 + s.void_ratio) / ball;
  const TriaxialConfig& t = cfg.triaxial;
  return balls * t.axial_strain_end / (t.inertial_number * std::sqrt(t.sigma3));
}

std::vector<StudyCase> study_cases(const std::vector<std::string>& inputs) {
  std::vector<std::string> files;
  for (const std::string& in : inputs) {
    if (fs::is_directory(in)) {
      std::vector<std::string> here;
      for (const auto& e : fs::directory_iterator(in))
        if (e.is_regular_file() && e.path().extension() == ".toml") here.push_back(e.path().string());
      if (here.empty()) throw std::runtime_error(in + ": no .toml configs in this folder");
      std::sort(here.begin(), here.end());
      files.insert(files.end(), here.begin(), here.end());
    } else if (fs::is_regular_file(in)) {
      files.push_back(in);
    } else {
      throw std::runtime_error(in + ": no such config file or folder");
    }
  }
  std::vector<StudyCase> cases;
  for (const std::string& f : files) {
    const Config cfg = load_config(f);  // a bad file stops the study before anything runs
    StudyCase c;
    c.config = f;
    c.material = cfg.run.material;
    c.name = fs::path(f).stem().string();
    c.cost = study_case_cost(cfg);
    if (cfg.has_periodic) c.job = "periodic";
    else if (cfg.has_specimen) c.job = "triaxial";
    else throw ConfigError(f + ": neither a [specimen] (membrane test) nor a [periodic] table: not a triaxial test");
    for (const StudyCase& o : cases)
      if (o.name == c.name) throw std::runtime_error(f + ": two cases named '" + c.name + "' (" + o.config + ")");
    cases.push_back(c);
  }
  return cases;
}

PeakComparison compare_peaks(const MeasuredData& data, const std::vector<StudyCase>& cases,
                             const std::vector<TestSummary>& summaries) {
  PeakComparison c;
  c.source = data.path;
  c.measure = data.q_measure;
  c.measured.assign(cases.size(), kNaN);
  c.error.assign(cases.size(), kNaN);
  Real sum = 0;
  for (std::size_t k = 0; k < cases.size(); ++k) {
    for (const TriaxialTest& t : data.tests)
      if (t.material == cases[k].material && std::fabs(t.sigma3 - summaries[k].sigma3) <= 1e-6 * t.sigma3)
        c.measured[k] = t.q_peak;
    const Real simulated = q_peak_as(summaries[k], c.measure);
    if (!(std::isfinite(c.measured[k]) && std::isfinite(simulated))) continue;
    c.error[k] = (simulated - c.measured[k]) / c.measured[k];
    sum += std::fabs(c.error[k]);
    if (c.matched == 0 || std::fabs(c.error[k]) > c.max_abs_error) c.max_abs_error = std::fabs(c.error[k]), c.worst = k;
    ++c.matched;
  }
  if (c.matched > 0) c.mean_abs_error = sum / c.matched;
  return c;
}

StudyTable study_table(const std::vector<StudyCase>& cases, const std::vector<int>& status, const std::string& output,
                       const std::vector<MeasuredData>& compare) {
  StudyTable t;
  t.summaries.resize(cases.size());
  t.ok.assign(cases.size(), false);
  for (std::size_t k = 0; k < cases.size(); ++k) {
    const std::string folder = output + "/" + cases[k].name;
    t.ok[k] = status[k] == 0 && fs::exists(folder + "/summary.csv");
    if (!t.ok[k]) {
      t.summaries[k].q_peak = kNaN;
      continue;
    }
    t.summaries[k] = read_summary(folder + "/summary.csv");
    if (summarise_series(folder, t.summaries[k])) write_summary(folder, t.summaries[k]);
  }
  for (const MeasuredData& d : compare) t.cmp.push_back(compare_peaks(d, cases, t.summaries));
  t.csv = "case,config,job,status,material," + summary_header();
  for (const PeakComparison& c : t.cmp) {
    const std::string stem = fs::path(c.source).stem().string();
    t.csv += ",q_peak_" + stem + "_kPa,error_" + stem + "_pct";
  }
  t.csv += "\n";
  for (std::size_t k = 0; k < cases.size(); ++k) {
    const StudyCase& c = cases[k];
    if (!t.ok[k]) {
      t.csv += c.name + "," + c.config + "," + c.job + "," + (status[k] < 0 ? "pending," : "failed,") + c.material + "\n";
      continue;
    }
    t.csv += c.name + "," + c.config + "," + c.job + ",ok," + c.material + "," + summary_values(t.summaries[k]);
    for (const PeakComparison& p : t.cmp) {
      char b[64];
      std::snprintf(b, sizeof b, ",%.2f,%.2f", p.measured[k] / 1e3, 100 * p.error[k]);
      t.csv += std::isfinite(p.error[k]) ? std::string(b) : std::string(",,");
    }
    t.csv += "\n";
  }
  return t;
}

}  // namespace dem
