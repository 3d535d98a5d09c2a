#include "measured.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <sstream>

namespace dem {

namespace {

constexpr Real kNaN = std::numeric_limits<Real>::quiet_NaN();

/// A column's quantity and the factor that turns the file's unit into SI.
struct ColumnSpec {
  std::string quantity;  ///< e.g. "q_peak", "eps_a", "material"
  Real scale = 1;
};

const std::map<std::string, Real> kStressUnits = {{"Pa", 1}, {"kPa", 1e3}, {"MPa", 1e6}};
const std::map<std::string, Real> kStrainUnits = {{"pct", 1e-2}, {"frac", 1}};
const std::map<std::string, const std::map<std::string, Real>*> kQuantities = {
    {"sigma3", &kStressUnits}, {"q", &kStressUnits},         {"q_peak", &kStressUnits}, {"q_end", &kStressUnits}, {"e_ini", &kStressUnits},
    {"q_1pct", &kStressUnits}, {"q_3pct", &kStressUnits},
    {"eps_a", &kStrainUnits},  {"eps_v", &kStrainUnits}, {"eps_a_peak", &kStrainUnits}};

std::string trim(const std::string& s) {
  const auto a = s.find_first_not_of(" \t\r");
  if (a == std::string::npos) return "";
  return s.substr(a, s.find_last_not_of(" \t\r") - a + 1);
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream s(line);
  std::string cell;
  while (std::getline(s, cell, ',')) out.push_back(trim(cell));
  if (!line.empty() && line.back() == ',') out.emplace_back();
  return out;
}

/// `at` is where in the file: "<path>:<line>" in a CSV, "<path>:/<material>/table row <k>" in HDF5.
[[noreturn]] void fail(const std::string& at, const std::string& column, const std::string& what) {
  throw DataError(at + (column.empty() ? "" : ":" + column) + ": " + what);
}

ColumnSpec parse_header(const std::string& at, const std::string& name) {
  if (name == "material" || name == "max_dilatancy") return {name, 1};
  const auto cut = name.rfind('_');
  if (cut != std::string::npos) {
    const std::string q = name.substr(0, cut), unit = name.substr(cut + 1);
    auto it = kQuantities.find(q);
    if (it != kQuantities.end()) {
      auto u = it->second->find(unit);
      if (u == it->second->end()) {
        std::string allowed;
        for (const auto& [k, v] : *it->second) allowed += (allowed.empty() ? "" : ", ") + k;
        fail(at, name, "unit '" + unit + "' does not parse for " + q + " (allowed: " + allowed + ")");
      }
      return {q, u->second};
    }
  }
  fail(at, name,
       "unknown column (allowed: material, sigma3_<unit>, eps_a_<unit>, q_<unit>, eps_v_<unit>, q_peak_<unit>, "
       "eps_a_peak_<unit>, q_end_<unit>, max_dilatancy, e_ini_<unit>, q_1pct_<unit>, q_3pct_<unit>)");
}

}  // namespace

MeasuredTextTable read_csv_table(const std::string& path) {
  std::ifstream f(path);
  if (!f) throw DataError(path + ": cannot be read");
  MeasuredTextTable t;
  std::string line;
  for (long n = 1; std::getline(f, line); ++n) {
    const std::string s = trim(line);
    if (s.empty() || s[0] == '#') continue;
    if (t.header.empty() && t.header_at.empty()) {
      t.header = split(s);
      t.header_at = path + ":" + std::to_string(n);
    } else {
      t.rows.push_back({path + ":" + std::to_string(n), split(s)});
    }
  }
  return t;
}

bool is_hdf5_path(const std::string& path) {
  const auto dot = path.rfind('.');
  const std::string ext = dot == std::string::npos ? "" : path.substr(dot);
  return ext == ".h5" || ext == ".hdf5";
}

MeasuredData load_measured(const std::string& path) {
  const MeasuredTextTable table = is_hdf5_path(path) ? read_measured_h5(path) : read_csv_table(path);
  if (table.header_at.empty()) throw DataError(path + ": no header line");
  MeasuredData d;
  d.path = path;
  std::vector<ColumnSpec> cols;
  const std::vector<std::string>& names = table.header;
  std::map<std::string, int> index;  // quantity -> column
  std::map<std::pair<std::string, Real>, std::size_t> test_of;
  for (const std::string& c : names) {
    cols.push_back(parse_header(table.header_at, c));
    if (index.count(cols.back().quantity)) fail(table.header_at, c, "column given twice");
    index[cols.back().quantity] = static_cast<int>(cols.size()) - 1;
  }
  d.curves = index.count("eps_a") > 0;
  const std::vector<std::string> need = d.curves ? std::vector<std::string>{"material", "sigma3", "eps_a", "q"}
                                                 : std::vector<std::string>{"material", "sigma3", "q_peak"};
  for (const std::string& q : need)
    if (!index.count(q))
      fail(table.header_at, "", "missing column '" + q + "'" + (q == "material" ? "" : " (with its unit, e.g. " + q +
                                                                (q.rfind("eps", 0) == 0 ? "_pct" : "_kPa") + ")"));
  if (!d.curves && index.count("eps_v")) fail(table.header_at, names[index["eps_v"]], "eps_v needs curves (an eps_a column)");
  for (const MeasuredTextTable::Row& row : table.rows) {
    const std::vector<std::string>& cells = row.cells;
    if (cells.size() != cols.size())
      fail(row.at, "", "has " + std::to_string(cells.size()) + " cells, the header " + std::to_string(cols.size()));
    auto number = [&](const std::string& q) {
      auto it = index.find(q);
      if (it == index.end()) return kNaN;
      const std::string& c = cells[it->second];
      char* end = nullptr;
      errno = 0;
      const double v = std::strtod(c.c_str(), &end);
      if (c.empty() || end != c.c_str() + c.size() || errno != 0 || !std::isfinite(v))
        fail(row.at, names[it->second], "'" + c + "' is not a number");
      return v * cols[it->second].scale;
    };
    const std::string material = cells[index["material"]];
    if (material.empty()) fail(row.at, "material", "empty");
    const Real sigma3 = number("sigma3");
    if (!(sigma3 > 0)) fail(row.at, names[index["sigma3"]], "confining pressure must be > 0");
    const auto key = std::make_pair(material, sigma3);
    auto it = test_of.find(key);
    if (it == test_of.end()) {
      MeasuredTest mt;
      mt.material = material;
      mt.sigma3 = sigma3;
      d.tests.push_back(mt);
      it = test_of.emplace(key, d.tests.size() - 1).first;
    } else if (!d.curves) {
      fail(row.at, "", "material " + material + " at " + std::to_string(sigma3 / 1e3) + " kPa given twice");
    }
    MeasuredTest& mt = d.tests[it->second];
    if (d.curves) {
      const Real ea = number("eps_a");
      if (!mt.eps_a.empty() && !(ea > mt.eps_a.back()))
        fail(row.at, names[index["eps_a"]], "axial strain must increase within a test (" + material + " at " +
                                                std::to_string(sigma3 / 1e3) + " kPa)");
      mt.eps_a.push_back(ea);
      mt.q.push_back(number("q"));
      if (index.count("eps_v")) mt.eps_v.push_back(number("eps_v"));
    } else {
      mt.q_peak = number("q_peak");
      mt.eps_a_peak = number("eps_a_peak");
      mt.q_end = number("q_end");
      mt.max_dilatancy = number("max_dilatancy");
      mt.e_ini = number("e_ini");
      mt.q_1pct = number("q_1pct");
      mt.q_3pct = number("q_3pct");
    }
  }
  if (d.tests.empty()) throw DataError(path + ": no data rows");
  if (d.curves)
    for (MeasuredTest& t : d.tests) summarise(t);
  return d;
}

ReferenceValues load_reference(const std::string& path, const std::function<void(const std::string&)>& known) {
  std::ifstream f(path);
  if (!f) throw DataError(path + ": cannot be read");
  ReferenceValues ref;
  ref.path = path;
  std::string line;
  for (long n = 1; std::getline(f, line); ++n) {
    const std::string t = trim(line);
    if (t.empty()) continue;
    if (t[0] == '#') {
      ref.comment += (ref.comment.empty() ? "" : " ") + trim(t.substr(1));
      continue;
    }
    const std::vector<std::string> cells = split(t);
    if (ref.parameters.empty()) {
      if (cells.empty() || cells[0] != "material") fail(path + ":" + std::to_string(n), cells.empty() ? "" : cells[0], "the first column must be 'material'");
      if (cells.size() < 2) fail(path + ":" + std::to_string(n), "", "no parameter columns");
      for (std::size_t c = 1; c < cells.size(); ++c) {
        try {
          known(cells[c]);
        } catch (const std::invalid_argument& e) {
          fail(path + ":" + std::to_string(n), cells[c], e.what());
        }
        ref.parameters.push_back(cells[c]);
      }
      continue;
    }
    if (cells.size() != ref.parameters.size() + 1)
      fail(path + ":" + std::to_string(n), "", "has " + std::to_string(cells.size()) + " cells, the header " +
                            std::to_string(ref.parameters.size() + 1));
    if (cells[0].empty()) fail(path + ":" + std::to_string(n), "material", "empty");
    for (std::size_t c = 0; c < ref.parameters.size(); ++c) {
      const std::string& v = cells[c + 1];
      char* end = nullptr;
      const double x = std::strtod(v.c_str(), &end);
      if (v.empty() || end != v.c_str() + v.size() || !std::isfinite(x))
        fail(path + ":" + std::to_string(n), ref.parameters[c], "'" + v + "' is not a number");
      ref.values[cells[0]][ref.parameters[c]] = x;
    }
  }
  if (ref.parameters.empty()) throw DataError(path + ": no header line");
  return ref;
}

namespace {
/// Mean of v over the rows whose axial strain lies within +-h of eps_a[i], h = min(half, distance to either end
/// of the curve): a window in strain, so that uneven row spacing does not change the smoothing, and symmetric,
/// so that a straight line comes out unchanged up to the very ends.
std::vector<Real> smooth(const std::vector<Real>& eps_a, const std::vector<Real>& v, Real half) {
  std::vector<Real> out(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) {
    const Real h = std::min({half, eps_a[i] - eps_a.front(), eps_a.back() - eps_a[i]}) + 1e-12;
    Real sum = v[i];
    int n = 1;
    for (std::size_t j = i; j-- > 0 && eps_a[j] >= eps_a[i] - h;) sum += v[j], ++n;
    for (std::size_t j = i + 1; j < v.size() && eps_a[j] <= eps_a[i] + h; ++j) sum += v[j], ++n;
    out[i] = sum / n;
  }
  return out;
}
}  // namespace

Real friction_angle_deg(Real q, Real sigma3) { return std::asin(q / (q + 2 * sigma3)) * 180 / M_PI; }

void summarise(MeasuredTest& t) {
  if (t.q.empty()) return;
  const std::vector<Real> q = smooth(t.eps_a, t.q, kSmoothHalfWidth);
  // The peak is sought where the window is whole: towards either end it shrinks to the end row alone, whose
  // scatter would pass for a peak (the last record of a plateau often does). A curve shorter than one window
  // is searched whole.
  std::size_t lo = 0, hi = q.size();
  while (lo < hi && t.eps_a[lo] - t.eps_a.front() < kSmoothHalfWidth - 1e-12) ++lo;
  while (hi > lo && t.eps_a.back() - t.eps_a[hi - 1] < kSmoothHalfWidth - 1e-12) --hi;
  if (lo >= hi) lo = 0, hi = q.size();
  const auto k = std::max_element(q.begin() + lo, q.begin() + hi) - q.begin();
  t.q_peak = q[k];
  t.eps_a_peak = t.eps_a[k];
  auto q_at = [&](Real e) {
    if (e < t.eps_a.front() || e > t.eps_a.back()) return kNaN;
    const auto j = std::lower_bound(t.eps_a.begin(), t.eps_a.end(), e) - t.eps_a.begin();
    if (j == 0) return q[0];
    const Real w = (e - t.eps_a[j - 1]) / (t.eps_a[j] - t.eps_a[j - 1]);
    return (1 - w) * q[j - 1] + w * q[j];
  };
  t.q_1pct = q_at(kEarlyStrain);
  t.q_3pct = q_at(kMidStrain);
  // q at the end: the mean over the last strain window (one raw row carries the full scatter).
  Real sum = 0;
  int n = 0;
  for (std::size_t i = t.q.size(); i-- > 0 && t.eps_a[i] >= t.eps_a.back() - kEndWindow;) sum += t.q[i], ++n;
  t.q_end = sum / n;
  // Initial stiffness: least-squares slope through the first row of q against eps_a over the first
  // kInitialWindow of strain (raw rows: smoothing would blur the start).
  Real sxy = 0, sxx = 0;
  for (std::size_t i = 1; i < t.q.size() && t.eps_a[i] - t.eps_a[0] <= kInitialWindow + 1e-12; ++i) {
    const Real x = t.eps_a[i] - t.eps_a[0];
    sxy += x * (t.q[i] - t.q[0]);
    sxx += x * x;
  }
  t.e_ini = sxx > 0 ? sxy / sxx : kNaN;
  t.max_dilatancy = kNaN;
  if (t.eps_v.empty()) return;
  // Maximum dilatancy -d eps_v / d eps_a: the slope of the smoothed eps_v over one window of strain.
  const std::vector<Real> ev = smooth(t.eps_a, t.eps_v, kSmoothHalfWidth);
  t.max_dilatancy = 0;
  for (std::size_t i = 0, j = 0; i < ev.size(); ++i) {
    while (j < ev.size() && t.eps_a[j] < t.eps_a[i] + 2 * kSmoothHalfWidth - 1e-12) ++j;
    if (j >= ev.size()) break;
    t.max_dilatancy = std::max(t.max_dilatancy, -(ev[j] - ev[i]) / (t.eps_a[j] - t.eps_a[i]));
  }
}

void check_pressures(const MeasuredData& d, const std::vector<Real>& sigma3) {
  for (const MeasuredTest& t : d.tests) {
    const bool known = std::any_of(sigma3.begin(), sigma3.end(),
                                   [&](Real s) { return std::fabs(s - t.sigma3) <= 1e-9 * std::max(s, t.sigma3); });
    if (!known) {
      std::ostringstream m;
      m << d.path << ": material " << t.material << " at sigma3 = " << t.sigma3 / 1e3
        << " kPa: no config for this pressure (configs have:";
      for (Real s : sigma3) m << " " << s / 1e3;
      m << " kPa)";
      throw DataError(m.str());
    }
  }
}

}  // namespace dem
