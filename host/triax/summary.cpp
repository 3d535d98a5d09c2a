#include "host/triax/summary.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "host/config/config.hpp"
#include "host/io/io_hdf5.hpp"
#include "host/triax/periodic_triaxial.hpp"
#include "host/triax/q_columns.hpp"
#include "host/triax/triaxial.hpp"
#include "host/util/ranks.hpp"
#include "host/util/text_format.hpp"

namespace dem {

namespace fs = std::filesystem;

namespace {

// Column names and scales of summary.csv: one place for the writer and the reader.
struct Column {
  const char* name;
  Real TestSummary::*field;
  double scale;           ///< file value = SI value x scale
  bool optional = false;  ///< NaN when a summary.csv lacks it (written before the column existed)
};
const Column kColumns[] = {
    {"sigma3_kPa", &TestSummary::sigma3, 1e-3},       {"mu_s", &TestSummary::mu_s, 1},
    {"mu_r", &TestSummary::mu_r, 1},                  {"void_ratio0", &TestSummary::void_ratio0, 1},
    {"q_peak_kPa", &TestSummary::q_peak, 1e-3},       {"phi_peak_deg", &TestSummary::phi_peak_deg, 1},
    {"eps_a_peak_pct", &TestSummary::eps_a_peak, 100}, {"q_end_kPa", &TestSummary::q_end, 1e-3},
    {"eps_a_end_pct", &TestSummary::eps_a_end, 100},  {"max_dilatancy", &TestSummary::max_dilatancy, 1},
    {"inertial_number", &TestSummary::inertial_number, 1},
    {"q_peak_area_kPa", &TestSummary::q_peak_area, 1e-3, true},
    {"q_peak_parabolic_kPa", &TestSummary::q_peak_parabolic, 1e-3, true},
    {"q_peak_membrane_kPa", &TestSummary::q_peak_membrane, 1e-3, true},
    {"q_peak_lw_kPa", &TestSummary::q_peak_lw, 1e-3, true},
};
// Provenance, after the numbers: text columns, optional for the reader (older summaries lack them).
const std::pair<const char*, std::string Provenance::*> kProvenanceColumns[] = {
    {"version", &Provenance::version}, {"backend", &Provenance::backend}, {"config", &Provenance::config},
    {"config_hash", &Provenance::config_hash}};

/// Where tools/<script> is: beside the executable's folder (build tree or install prefix), else the sources.
std::string find_tool(const std::string& script) {
  std::vector<fs::path> roots;
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) roots = {exe.parent_path() / "..", exe.parent_path() / "../share/triaxdem"};
#ifdef TRIAXDEM_SOURCE_DIR
  roots.emplace_back(TRIAXDEM_SOURCE_DIR);
#endif
  for (const fs::path& r : roots)
    if (fs::exists(r / "tools" / script)) return fs::weakly_canonical(r / "tools" / script).string();
  return "";
}

}  // namespace

std::string summary_header() {
  std::string h = "kind,balls,wall_s";
  for (const Column& c : kColumns) h += std::string(",") + c.name;
  for (const auto& [name, field] : kProvenanceColumns) h += std::string(",") + name;
  return h + ",seed";
}

std::string summary_values(const TestSummary& s) {
  char b[64];
  std::snprintf(b, sizeof b, "%s,%ld,%.1f", s.kind.c_str(), s.balls, s.wall_seconds);
  std::string row = b;
  for (const Column& c : kColumns) {
    std::snprintf(b, sizeof b, ",%.6g", s.*(c.field) * c.scale);
    row += b;
  }
  for (const auto& [name, field] : kProvenanceColumns) {
    std::string text = s.provenance.*field;
    std::replace(text.begin(), text.end(), ',', ';');  // one cell, for this file's plain comma splitting
    row += "," + text;
  }
  return row + "," + std::to_string(s.provenance.seed);
}

void write_summary(const std::string& folder, const TestSummary& s) {
  io::write_text_atomic(folder + "/summary.csv", summary_header() + "\n" + summary_values(s) + "\n");
}

namespace {

/// What every test's summary takes alike from its config and its result's curve values (take_curve_values).
template <class Result>
TestSummary curve_summary(const Config& cfg, const Result& r, long balls, const char* kind) {
  TestSummary s;
  s.kind = kind;
  s.mu_s = cfg.ball.mu_s;
  s.mu_r = cfg.ball.mu_r;
  s.balls = balls;
  s.q_peak = r.q_peak;
  s.phi_peak_deg = r.phi_peak_deg;
  s.eps_a_peak = r.eps_a_peak;
  s.q_end = r.q_end;
  s.max_dilatancy = r.max_dilatancy;
  s.wall_seconds = r.wall_seconds;
  s.provenance = provenance_of(cfg);
  return s;
}

}  // namespace

TestSummary summary_of(const Config& cfg, const TriaxialResult& r, long balls) {
  TestSummary s = curve_summary(cfg, r, balls, "membrane");
  s.sigma3 = cfg.triaxial.sigma3;
  s.void_ratio0 = r.void_ratio_consolidated;
  if (!r.records.empty())
    for (const QColumn& c : kQColumns) s.*c.peak = curves_of(r, c.record, s.sigma3).q_peak;
  s.eps_a_end = r.records.empty() ? 0 : r.records.back().eps_a;
  s.inertial_number = r.inertial_number;
  return s;
}

TestSummary summary_of(const Config& cfg, const PeriodicTriaxialResult& r, long balls) {
  TestSummary s = curve_summary(cfg, r, balls, cfg.periodic.boundary == CellBoundary::walls ? "walls" : "periodic");
  s.sigma3 = r.params.sigma3;
  s.void_ratio0 = r.void_ratio0;
  for (const QColumn& c : kQColumns) s.*c.peak = r.q_peak;  // one q: every measure's
  s.eps_a_end = r.series.empty() ? 0 : r.series.back().eps_a;
  s.inertial_number = r.inertial;
  return s;
}

TestSummary read_summary(const std::string& path) {
  std::ifstream f(path);
  if (!f) throw std::runtime_error(path + ": cannot be read");
  std::string h, v;
  std::getline(f, h);
  std::getline(f, v);
  const std::vector<std::string> names = split_fields(h), values = split_fields(v);
  if (names.size() != values.size()) throw std::runtime_error(path + ": line 2 has " + std::to_string(values.size()) +
                                                              " cells, the header " + std::to_string(names.size()));
  std::map<std::string, std::string> m;
  for (std::size_t k = 0; k < names.size(); ++k) m[names[k]] = values[k];
  auto get = [&](const std::string& name) -> const std::string& {
    auto it = m.find(name);
    if (it == m.end()) throw std::runtime_error(path + ": column '" + name + "' missing");
    return it->second;
  };
  TestSummary s;
  s.kind = get("kind");
  s.balls = std::stol(get("balls"));
  s.wall_seconds = std::stod(get("wall_s"));
  for (const Column& c : kColumns)
    s.*(c.field) = c.optional && !m.count(c.name) ? kNaN : std::stod(get(c.name)) / c.scale;
  for (const auto& [name, field] : kProvenanceColumns)
    if (m.count(name)) s.provenance.*field = m[name];
  if (m.count("seed")) s.provenance.seed = std::stol(m["seed"]);
  return s;
}

Real q_peak_as(const TestSummary& s, QMeasure m) {
  const QColumn* c = s.kind == "periodic" ? nullptr : q_column(m);  // no boundary: its one q is every measure's
  return c ? s.*c->peak : s.q_peak;
}

bool summarise_series(const std::string& folder, TestSummary& s) {
  const std::string path = folder + "/series.csv";
  if (!fs::exists(path)) return false;
  const MeasuredTextTable t = read_csv_table(path);
  const auto& h = t.header;
  const auto n = static_cast<std::ptrdiff_t>(h.size());
  auto column = [&](const char* name) { return std::find(h.begin(), h.end(), name) - h.begin(); };
  const auto ke = column("eps_a_pct"), kq = column("q_kPa"), kv = column("eps_v_pct");
  if (ke == n || kq == n || kv == n || t.rows.empty()) return false;
  struct Row {
    Real eps_a, q, eps_v;
  };
  // The rows with q from column kq, or nothing when a row does not read.
  auto rows_of = [&](std::ptrdiff_t kq_col) -> std::optional<std::vector<Row>> {
    std::vector<Row> rows;
    for (const MeasuredTextTable::Row& r : t.rows) {
      if (static_cast<std::ptrdiff_t>(r.cells.size()) != n) return std::nullopt;
      try {
        rows.push_back({std::stod(r.cells[ke]) / 100, std::stod(r.cells[kq_col]) * 1e3, std::stod(r.cells[kv]) / 100});
      } catch (const std::exception&) {
        return std::nullopt;
      }
    }
    return rows;
  };
  const auto rows = rows_of(kq);
  if (!rows) return false;
  take_curve_values(s, summarised(*rows, s.sigma3));
  for (const QColumn& c : kQColumns) {
    const auto k = column(c.series_column);
    const auto measured = k == n ? std::nullopt : rows_of(k);
    if (measured) s.*c.peak = summarised(*measured, s.sigma3).q_peak;
  }
  return true;
}

bool run_plot_script(const std::string& script, const std::vector<std::string>& args) {
  if (!ranks::leader()) return true;  // the leader draws it
  const std::string path = find_tool(script);
  if (path.empty()) {
    std::fprintf(stderr, "triaxdem: tools/%s not found: no plot drawn\n", script.c_str());
    return false;
  }
  // Debian's interpreter first: python3-matplotlib is installed for it, not for a python3 earlier on PATH.
  std::string cmd = std::string(fs::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3") + " '" + path + "'";
  for (const std::string& a : args) cmd += " '" + a + "'";
  cmd += " 2>&1";
  const int rc = std::system(cmd.c_str());
  if (rc != 0) {
    std::fprintf(stderr, "triaxdem: %s failed (python3 with matplotlib is needed for the plots): no plot drawn\n",
                 script.c_str());
    return false;
  }
  return true;
}

}  // namespace dem
