#include "host/study/calibration_session.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "host/fit/two_fidelity.hpp"
#include "host/io/io_hdf5.hpp"
#include "host/lab/wall_layer.hpp"
#include "host/util/text_format.hpp"

namespace dem {

/// Between walls the specimen's size is part of the test (the walls' looser layer falls as N^-1/3): tests that give
/// no specimen_balls are taken to be of the walled cell's balls, with a note, where the cell's bias check would have
/// extrapolated the cell to an infinite specimen and counted the walls' share as the simulator's bias.
void take_walled_size(const Config& cell, MeasuredData& data) {
  if (cell.periodic.boundary != CellBoundary::walls) return;
  const Real balls = static_cast<Real>(cell.particles.count * std::max(cell.calibrate.cell_factor, 1L));
  bool took = false;
  for (TriaxialTest& t : data.tests)
    if (!std::isfinite(t.specimen_balls)) {
      t.specimen_balls = balls;
      took = true;
    }
  Real largest = 0;
  for (const TriaxialTest& t : data.tests) largest = std::max(largest, t.specimen_balls);
  if (larger_specimen(largest, balls))
    data.notes.push_back(
        "the walled cell of " + fmt("%.0f", balls) + " balls is smaller than the data's specimen of " +
        fmt("%.0f", largest) + ": its walls' looser layer is a larger share of it (the share falls as N^-1/3), so " +
        (cell.calibrate.walled_match == "interior"
             ? std::string("it is matched to the data's void ratio as a specimen of the data's balls would pack, its "
                           "layer measured and scaled to their size ([calibrate] walled_match = \"interior\")")
             : std::string("matched whole to the data's void ratio ([calibrate] walled_match = \"whole\") its "
                           "interior packs denser")) +
        "; the cell's bias check measures what differs, with both preparation frictions, and a walled cell of the "
        "data's balls ([particles] count) avoids it");
  if (took)
    data.notes.push_back("no specimen_balls: the walled cell takes its " + fmt("%.0f", balls) +
                         " balls as the data's specimen (between walls the size is part of the test, and the cell's "
                         "bias is not extrapolated to an infinite one); give specimen_balls where the data's specimen "
                         "differs");
}

void check_specimen_sizes(const Config& base, const Config& cell, const MeasuredData& data) {
  const Real balls = static_cast<Real>(cell.particles.count * std::max(cell.calibrate.cell_factor, 1L));
  for (const TriaxialTest& t : data.tests)
    if (std::isfinite(t.specimen_balls) && t.specimen_balls < balls)
      throw DataError(data.path + ": specimen_balls " + fmt("%.0f", t.specimen_balls) + " (" + t.material + " at " +
                      fmt("%g kPa", 1e-3 * t.sigma3) + ") is below the " + fmt("%.0f", balls) + " balls of the "
                      "simulator's cell (" + base.path + ": [particles] count" +
                      (cell.calibrate.cell_factor > 1 ? " times [calibrate] cell_factor" : "") + "): the cell's bias is "
                      "measured on larger cells and extrapolated toward larger specimens only; give the cell the "
                      "data's balls or fewer");
}

/// Takes the tests at --hold-out's pressure out of `data` and returns them. Refused (DataError naming the file, the
/// option and the data's pressures) where no test has that pressure or a material the job calibrates (--material)
/// would keep none.
std::vector<TriaxialTest> hold_out(const CalibrationOptions& o, MeasuredData& data) {
  if (!std::isfinite(o.hold_out_kPa)) return {};
  std::vector<TriaxialTest> kept, held;
  std::string pressures;
  for (const TriaxialTest& t : data.tests) {
    const bool at = std::fabs(1e-3 * t.sigma3 - o.hold_out_kPa) < 0.5;  // within the half kPa the files are given in
    (at ? held : kept).push_back(t);
    if (pressures.find(fmt(" %g,", 1e-3 * t.sigma3)) == std::string::npos) pressures += fmt(" %g,", 1e-3 * t.sigma3);
  }
  if (!pressures.empty()) pressures.pop_back();
  const std::string held_kPa = fmt("%g kPa", o.hold_out_kPa);
  if (held.empty())
    throw DataError(data.path + ": --hold-out " + held_kPa + ": no test at that pressure (the data's, kPa:" + pressures +
                    ")");
  // With --material only that material's tests are fitted and predicted: another material's test at the pressure
  // would be held out of nothing.
  if (!o.material.empty() &&
      std::none_of(held.begin(), held.end(), [&](const TriaxialTest& t) { return t.material == o.material; })) {
    std::string own;
    for (const TriaxialTest& t : data.tests)
      if (t.material == o.material && own.find(fmt(" %g,", 1e-3 * t.sigma3)) == std::string::npos)
        own += fmt(" %g,", 1e-3 * t.sigma3);
    if (!own.empty()) own.pop_back();
    throw DataError(data.path + ": --hold-out " + held_kPa + ": material " + o.material + " has no test at that "
                    "pressure (its pressures, kPa:" + own + ")");
  }
  for (const TriaxialTest& h : held)
    if ((o.material.empty() || h.material == o.material) && std::none_of(kept.begin(), kept.end(), [&](const TriaxialTest& t) { return t.material == h.material; }))
      throw DataError(data.path + ": --hold-out " + held_kPa + ": material " + h.material +
                      " has no other test to fit (the data's pressures, kPa:" + pressures + ")");
  data.tests = kept;
  data.notes.push_back("held out: the tests at " + held_kPa + " are left out of the fit and predicted at the end");
  return held;
}

namespace {

/// The inputs that decide a job's results, a line each ("data <hash of the file's bytes>"): a resumed folder's runs
/// belong to the same lines.
std::vector<std::pair<std::string, std::string>> job_inputs(const Config& base, const CalibrationOptions& o) {
  const auto bytes_hash = [](const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    return std::to_string(std::hash<std::string>{}(bytes));
  };
  std::string free;
  for (const std::string& f : o.free) free += f + " ";
  return {{"data", bytes_hash(o.data)},
          {"--compression", o.compression.empty() ? "" : bytes_hash(o.compression)},
          {"config", std::to_string(std::hash<std::string>{}(base.fingerprint))},
          {"--free", free},
          {"--material", o.material},
          {"--reference-test", o.reference_test},
          {"--predict", o.predict},
          {"--noise", o.noise},
          {"--hold-out", std::isfinite(o.hold_out_kPa) ? fmt("%g", o.hold_out_kPa) : ""}};
}

std::string inputs_path(const std::string& folder) { return folder + "/job_inputs.txt"; }

}  // namespace

void record_job_inputs(const Config& base, const CalibrationOptions& o, const std::string& folder) {
  std::string text;
  for (const auto& [key, value] : job_inputs(base, o)) text += key + " " + value + "\n";
  io::write_text_atomic(inputs_path(folder), text);
}

void check_resumed_inputs(const Config& base, const CalibrationOptions& o, const std::string& kind) {
  if (o.resume.empty()) return;
  std::ifstream in(inputs_path(o.resume));
  if (!in) return;  // a folder from before the record: its inputs cannot be checked (the job says so when it resumes)
  std::map<std::string, std::string> was;
  for (std::string line; std::getline(in, line);) {
    const std::string::size_type sp = line.find(' ');
    if (sp != std::string::npos) was[line.substr(0, sp)] = line.substr(sp + 1);
  }
  for (const auto& [key, value] : job_inputs(base, o))
    if (was.count(key) && was[key] != value)
      throw std::invalid_argument("--resume " + o.resume + ": the " + kind + " there ran with another " +
                                  (key == "data" ? "data file (its bytes differ from " + o.data + ")"
                                   : key == "--compression" ? "--compression file (its bytes differ from " +
                                                                   (o.compression.empty() ? "none" : o.compression) + ")"
                                   : key == "config" ? "config (" + base.path + " differs in a key that decides runs)"
                                                     : key + " ('" + was[key] + "', now '" + value + "')") +
                                  ": a resume continues the same job; start a new folder with -o");
}

void check_enough_data(const CalibrationOptions& o, const MeasuredData& data, std::size_t free) {
  if (data.curves) return;  // a curve gives tens of compared values
  std::map<std::string, std::size_t> values;
  for (const TriaxialTest& t : data.tests) {
    if (!o.material.empty() && t.material != o.material) continue;
    for (Real v : {t.q_peak, t.eps_a_peak, t.q_end, t.max_dilatancy, t.e_ini, t.q_1pct, t.q_3pct})
      values[t.material] += std::isfinite(v) ? 1 : 0;
  }
  for (const auto& [material, n] : values)
    if (n < free)
      throw DataError(data.path + ": material " + material + " gives " + std::to_string(n) + " summary value" +
                      (n == 1 ? "" : "s") + " for " + std::to_string(free) + " free parameters ([calibrate] free): " +
                      "fewer data than parameters leave a ridge of equal fits, each with chi2 0 (allowed: at least " +
                      std::to_string(free) + "): give more tests or values (q_peak, eps_a_peak, q_end, ...), or free " +
                      "fewer parameters");
}

}  // namespace dem
