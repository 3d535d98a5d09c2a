#include "host/data/measured.hpp"
#include "host/util/text_format.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <optional>
#include <set>
#include <sstream>
#include <tuple>

namespace dem {

namespace {

/// Sands stay below e ~ 1.2 and soft clays below ~ 4: a larger value is something else (a porosity in percent).
constexpr Real kMaxVoidRatio = 5;
// A curve of one or two rows has no shape: its peak, stiffness and dilatancy would be read off single points (a file
// with one point per test started a calibration). Three rows are the fewest with a peak between them.
constexpr std::size_t kMinCurveRows = 3;

/// A column's quantity and the factor that turns the file's unit into SI.
struct ColumnSpec {
  std::string quantity;  ///< e.g. "q_peak", "eps_a", "material", "q_sd" (a standard deviation of q)
  Real scale = 1;
};

const std::map<std::string, Real> kStressUnits = {{"Pa", 1}, {"kPa", 1e3}, {"MPa", 1e6}};
const std::map<std::string, Real> kStrainUnits = {{"pct", 1e-2}, {"frac", 1}};
const std::map<std::string, const std::map<std::string, Real>*> kQuantities = {
    {"sigma3", &kStressUnits}, {"q", &kStressUnits},         {"q_peak", &kStressUnits}, {"q_end", &kStressUnits}, {"e_ini", &kStressUnits},
    {"q_1pct", &kStressUnits}, {"q_3pct", &kStressUnits},
    {"eps_a", &kStrainUnits},  {"eps_v", &kStrainUnits}, {"eps_a_peak", &kStrainUnits}};
const std::set<std::string> kUnitless = {"material",       "test",       "max_dilatancy", "max_dilatancy_sd",
                                         "void_ratio",     "void_ratio_sd", "porosity",   "porosity_sd",
                                         "specimen_balls", "q_measure"};
/// The quantities whose standard deviation a file can give: a curve's rows are q and eps_v; a summary row is
/// its values (sigma3 is the test's key, not a measurement).
const std::vector<std::string> kCurveSd = {"q", "eps_v"};
const std::vector<std::string> kSummarySd = {"q_peak", "eps_a_peak", "q_end",  "max_dilatancy",
                                              "e_ini",  "q_1pct",     "q_3pct"};


std::string str(Real v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

bool is_sd(const std::string& quantity) {
  return quantity.size() > 3 && quantity.compare(quantity.size() - 3, 3, "_sd") == 0;
}

[[noreturn]] void fail(const std::string& at, const std::string& column, const std::string& what) {
  throw DataError(at, column, what);
}

Real unit_scale(const std::string& at, const std::string& name, const std::string& quantity,
                const std::map<std::string, Real>& units, const std::string& unit) {
  auto u = units.find(unit);
  if (u != units.end()) return u->second;
  std::string allowed;
  for (const auto& [k, v] : units) allowed += (allowed.empty() ? "" : ", ") + k;
  fail(at, name, "unit '" + unit + "' does not parse for " + quantity + " (allowed: " + allowed + ")");
}

ColumnSpec parse_header(const std::string& at, const std::string& name) {
  if (kUnitless.count(name)) return {name, 1};
  const auto cut = name.rfind('_');
  if (cut != std::string::npos) {
    const std::string q = name.substr(0, cut), unit = name.substr(cut + 1);
    auto it = kQuantities.find(is_sd(q) ? q.substr(0, q.size() - 3) : q);
    if (it != kQuantities.end()) return {q, unit_scale(at, name, q, *it->second, unit)};
  }
  if (name.empty())
    fail(at, "(an empty name)", "a column without a name: a comma at the end of the header, or two together? (allowed: "
         "one name per column)");
  fail(at, name,
       "unknown column (allowed: material, test, sigma3_<unit>, eps_a_<unit>, q_<unit>, eps_v_<unit>, q_peak_<unit>, "
       "eps_a_peak_<unit>, q_end_<unit>, max_dilatancy, e_ini_<unit>, q_1pct_<unit>, q_3pct_<unit>, "
       "<quantity>_sd_<unit>, max_dilatancy_sd, void_ratio or porosity, void_ratio_sd, porosity_sd, specimen_balls, "
       "q_measure)");
}

/// The header: each column's quantity and scale, and the column of each quantity.
struct Columns {
  std::vector<std::string> names;
  std::vector<ColumnSpec> specs;
  std::map<std::string, std::size_t> index;
  bool has(const std::string& q) const { return index.count(q) > 0; }
  const std::string& name(const std::string& q) const { return names[index.at(q)]; }
};

Columns read_columns(const MeasuredTextTable& table) {
  Columns c;
  c.names = table.header;
  for (const std::string& n : c.names) {
    c.specs.push_back(parse_header(table.header_at, n));
    if (!c.index.emplace(c.specs.back().quantity, c.specs.size() - 1).second)
      fail(table.header_at, n, "column given twice");
  }
  return c;
}

std::string sd_names(const std::vector<std::string>& quantities) {
  std::string s;
  for (const std::string& q : quantities)
    s += (s.empty() ? "" : ", ") + q + "_sd" + (kQuantities.count(q) ? "_<unit>" : "");
  return s + ", void_ratio_sd, porosity_sd";
}

void check_sd_column(const Columns& c, bool curves, const std::string& at, const std::string& q) {
  const std::string of = q.substr(0, q.size() - 3);
  const std::vector<std::string>& allowed = curves ? kCurveSd : kSummarySd;
  if (of != "void_ratio" && of != "porosity" && std::find(allowed.begin(), allowed.end(), of) == allowed.end())
    fail(at, c.name(q), std::string("a ") + (curves ? "curve" : "summary") + " file has no standard deviation of " +
                            of + " (allowed: " + sd_names(allowed) + ")");
  if (!c.has(of)) fail(at, c.name(q), "a standard deviation of " + of + ", which the file does not give");
}

void check_columns(const Columns& c, bool curves, const std::string& at) {
  const std::vector<std::string> need = curves ? std::vector<std::string>{"material", "sigma3", "eps_a", "q"}
                                               : std::vector<std::string>{"material", "sigma3", "q_peak"};
  for (const std::string& q : need)
    if (!c.has(q))
      fail(at, "", "missing column '" + q + "'" + (q == "material" ? "" : " (with its unit, e.g. " + q +
                                                   (q.rfind("eps", 0) == 0 ? "_pct" : "_kPa") + ")"));
  if (!curves && c.has("eps_v")) fail(at, c.name("eps_v"), "eps_v needs curves (an eps_a column)");
  if (curves)
    for (const std::string& q : kSummarySd)
      if (c.has(q))
        fail(at, c.name(q), q + " is a summary column, and a file with an eps_a column is curves, whose summary is read "
                                "off the curves: give curves or summary points, one kind a file");
  if (c.has("void_ratio") && c.has("porosity")) fail(at, c.name("porosity"), "give void_ratio or porosity, not both");
  for (const ColumnSpec& s : c.specs)
    if (is_sd(s.quantity)) check_sd_column(c, curves, at, s.quantity);
}

/// One row's cells by quantity; its refusals name the row and the column.
struct RowReader {
  const Columns& cols;
  const MeasuredTextTable::Row& row;

  bool has(const std::string& q) const { return cols.has(q); }
  const std::string& cell(const std::string& q) const { return row.cells[cols.index.at(q)]; }
  [[noreturn]] void refuse(const std::string& q, const std::string& what) const { fail(row.at, cols.name(q), what); }

  /// In SI; NaN when the file has no such column.
  Real number(const std::string& q) const {
    if (!has(q)) return kNaN;
    const std::optional<double> v = parse_number(cell(q));
    if (!v || !std::isfinite(*v)) refuse(q, "'" + cell(q) + "' is not a number");
    return *v * cols.specs[cols.index.at(q)].scale;
  }

  /// The standard deviation of quantity q, in SI; NaN when the file gives none.
  Real sd(const std::string& q) const {
    const std::string c = q + "_sd";
    if (!has(c)) return kNaN;
    if (cell(c).empty()) refuse(c, "missing for part of a test: give it on every row or on none");
    const std::optional<double> v = parse_number(cell(c));
    if (!v) refuse(c, "'" + cell(c) + "' is not a number");
    const Real s = *v * cols.specs[cols.index.at(c)].scale;
    if (!(std::isfinite(s) && s > 0)) refuse(c, "standard deviation must be > 0 and finite, not '" + cell(c) + "'");
    return s;
  }
};

/// A deviator beyond kMaxStressRatio sigma3 is no triaxial test but a slip of unit or sign.
Real stress(const RowReader& r, const std::string& q, Real sigma3) {
  const Real v = r.number(q);
  const Real limit = kMaxStressRatio * sigma3;
  if (std::fabs(v) > limit)
    r.refuse(q, str(v / 1e3) + " kPa is implausible at sigma3 = " + str(sigma3 / 1e3) + " kPa (allowed: |" + q +
                    "| <= " + str(kMaxStressRatio) + " sigma3 = " + str(limit / 1e3) + " kPa)");
  return v;
}

Real strain(const RowReader& r, const std::string& q) {
  const Real v = r.number(q);
  if (std::fabs(v) > kMaxStrain)
    r.refuse(q, str(100 * v) + "% is implausible (allowed: |" + q + "| <= " + str(100 * kMaxStrain) + "%)");
  return v;
}

/// The specimen's void ratio and its standard deviation (NaN where not given); a porosity n is taken as
/// e = n / (1 - n), its standard deviation through de/dn = 1 / (1 - n)^2.
std::pair<Real, Real> void_ratio_of(const RowReader& r) {
  if (r.has("void_ratio")) {
    const Real e = r.number("void_ratio");
    if (!(e > 0 && e <= kMaxVoidRatio)) r.refuse("void_ratio", "void ratio must be in (0, " + str(kMaxVoidRatio) + "]");
    return {e, r.sd("void_ratio")};
  }
  if (!r.has("porosity")) return {kNaN, kNaN};
  const Real n = r.number("porosity");
  if (!(n > 0 && n < 1)) r.refuse("porosity", "porosity must be in (0, 1) (a fraction)");
  return {n / (1 - n), r.sd("porosity") / ((1 - n) * (1 - n))};
}

/// The state is one per test, repeated on its rows: a row that differs is a typo or two tests under one key.
void check_same_state(const RowReader& r, const TriaxialTest& row, const TriaxialTest& t, const std::string& first) {
  const std::string e = r.has("porosity") ? "porosity" : "void_ratio";
  const std::string why = " differs from the test's first row, " + first + " (one value per test, on each of its rows)";
  if (r.has(e) && row.void_ratio != t.void_ratio) r.refuse(e, "'" + r.cell(e) + "'" + why);
  if (r.has(e + "_sd") && row.void_ratio_sd != t.void_ratio_sd)
    r.refuse(e + "_sd", "'" + r.cell(e + "_sd") + "'" + why);
  if (r.has("specimen_balls") && row.specimen_balls != t.specimen_balls)
    r.refuse("specimen_balls", "'" + r.cell("specimen_balls") + "'" + why);
}

/// Tests by material, pressure and label, and the row where each begins.
struct TestIndex {
  std::map<std::tuple<std::string, Real, std::string>, std::size_t> of;
  std::vector<std::string> first_at;
};

TriaxialTest& test_of(const RowReader& r, MeasuredData& d, TestIndex& tests) {
  TriaxialTest key;
  key.material = r.cell("material");
  if (key.material.empty()) r.refuse("material", "empty");
  key.sigma3 = r.number("sigma3");
  if (!(key.sigma3 > 0)) r.refuse("sigma3", "confining pressure must be > 0");
  if (r.has("test")) key.replicate = r.cell("test");
  std::tie(key.void_ratio, key.void_ratio_sd) = void_ratio_of(r);
  if (r.has("specimen_balls")) {
    key.specimen_balls = r.number("specimen_balls");
    if (!(key.specimen_balls >= 1 && key.specimen_balls <= 1e12 && std::floor(key.specimen_balls) == key.specimen_balls))
      r.refuse("specimen_balls", "particles in the specimen: a whole number in [1, 1e12]");
  }
  const auto [it, is_new] = tests.of.emplace(std::make_tuple(key.material, key.sigma3, key.replicate), d.tests.size());
  if (is_new) {
    tests.first_at.push_back(r.row.at);
    return d.tests.emplace_back(key);
  }
  const std::string& first = tests.first_at[it->second];
  if (!d.curves) fail(r.row.at, "", "material " + describe_test(key) + " given twice (first on " + first + ")");
  check_same_state(r, key, d.tests[it->second], first);
  return d.tests[it->second];
}

void read_curve_row(const RowReader& r, TriaxialTest& t) {
  const Real ea = strain(r, "eps_a");
  if (ea < 0) r.refuse("eps_a", str(100 * ea) + "%: axial strain is >= 0 (compression positive, from the start of shear)");
  // A curve that starts again from its first strain is a test given twice (or replicates without labels), not a typo.
  if (t.eps_a.size() >= 3 && ea <= t.eps_a.front())
    r.refuse("eps_a", str(100 * ea) + "% starts the curve of " + describe_test(t) + " again (its first row: " +
                          str(100 * t.eps_a.front()) + "%): a test given twice; replicates need a test column, a label "
                          "each");
  if (!t.eps_a.empty() && !(ea > t.eps_a.back()))
    r.refuse("eps_a", "axial strain must increase within a test (" + describe_test(t) + ")");
  t.eps_a.push_back(ea);
  t.q.push_back(stress(r, "q", t.sigma3));
  if (r.has("eps_v")) t.eps_v.push_back(strain(r, "eps_v"));
  if (r.has("q_sd")) t.q_sd.push_back(r.sd("q"));
  if (r.has("eps_v_sd")) t.eps_v_sd.push_back(r.sd("eps_v"));
}

void read_summary_row(const RowReader& r, TriaxialTest& t) {
  t.q_peak = stress(r, "q_peak", t.sigma3);
  t.eps_a_peak = strain(r, "eps_a_peak");
  t.q_end = stress(r, "q_end", t.sigma3);
  t.max_dilatancy = r.number("max_dilatancy");
  t.e_ini = r.number("e_ini");
  if (t.e_ini < 0) r.refuse("e_ini", "initial stiffness must be >= 0");
  t.q_1pct = stress(r, "q_1pct", t.sigma3);
  t.q_3pct = stress(r, "q_3pct", t.sigma3);
  for (const std::string& q : kSummarySd)
    if (r.has(q + "_sd")) t.summary_sd[q] = r.sd(q);
}

/// The file's q measure: one name, the same on every row.
void read_q_measure(const RowReader& r, MeasuredData& d) {
  if (!r.has("q_measure")) return;
  const std::string& v = r.cell("q_measure");
  QMeasure m = QMeasure::kFixedArea;
  bool known = false;
  std::string allowed;
  for (int k = 0; k < kQMeasures; ++k) {
    allowed += (k ? ", " : "") + std::string(kQMeasureNames[k]);
    if (v == kQMeasureNames[k]) m = static_cast<QMeasure>(k), known = true;
  }
  if (!known) r.refuse("q_measure", "'" + v + "' is not a q measure (allowed: " + allowed + ")");
  if (d.q_measure_given && m != d.q_measure)
    r.refuse("q_measure", "'" + v + "' differs from the first row's '" + name_of(d.q_measure) +
                              "' (one measure per file)");
  d.q_measure = m;
  d.q_measure_given = true;
}

/// Near-equal pressures of one material are taken as one (a lab's 100 kPa is logged as 99.6 or 101.2), which
/// the user should hear of: they may have been meant as a series.
void note_replicates(MeasuredData& d) {
  for (const std::vector<std::size_t>& g : replicate_groups(d.tests)) {
    std::set<Real> p;
    for (std::size_t k : g) p.insert(d.tests[k].sigma3);
    if (p.size() < 2) continue;
    std::string list;
    for (auto it = p.begin(); it != p.end(); ++it)
      list += (it == p.begin() ? "" : std::next(it) == p.end() ? " and " : ", ") + str(*it / 1e3);
    d.notes.push_back(d.path + ": material " + d.tests[g[0]].material + ": tests at " + list +
                      " kPa differ by less than " + str(100 * kReplicateTolerance) +
                      "%: taken as replicates of one pressure");
  }
}

}  // namespace

std::string describe_test(const TriaxialTest& t) {
  return t.material + " at " + str(t.sigma3 / 1e3) + " kPa" + (t.replicate.empty() ? "" : ", test " + t.replicate);
}

Real column_scale(const std::string& at, const std::string& column, bool stress) {
  const auto cut = column.rfind('_');
  const std::string unit = cut == std::string::npos ? "" : column.substr(cut + 1);
  return unit_scale(at, column, column.substr(0, cut), stress ? kStressUnits : kStrainUnits, unit);
}

bool is_hdf5_path(const std::string& path) {
  const auto dot = path.rfind('.');
  const std::string ext = dot == std::string::npos ? "" : path.substr(dot);
  return ext == ".h5" || ext == ".hdf5";
}

std::vector<std::vector<std::size_t>> replicate_groups(const std::vector<TriaxialTest>& tests) {
  std::vector<std::vector<std::size_t>> groups;
  std::vector<bool> taken(tests.size());
  for (std::size_t i = 0; i < tests.size(); ++i) {
    if (taken[i]) continue;
    groups.push_back({i});
    for (std::size_t j = i + 1; j < tests.size(); ++j) {
      const Real a = tests[i].sigma3, b = tests[j].sigma3;
      const bool near = std::fabs(a - b) < kReplicateTolerance * std::max(a, b);
      if (!taken[j] && tests[j].material == tests[i].material && near) {
        taken[j] = true;
        groups.back().push_back(j);
      }
    }
  }
  return groups;
}

MeasuredData load_measured(const std::string& path) {
  const MeasuredTextTable table = is_hdf5_path(path) ? read_measured_h5(path) : read_csv_table(path);
  if (table.header_at.empty()) throw DataError(path + ": no header line");
  MeasuredData d;
  d.path = path;
  const Columns cols = read_columns(table);
  d.curves = cols.has("eps_a");
  check_columns(cols, d.curves, table.header_at);
  TestIndex tests;
  for (const MeasuredTextTable::Row& row : table.rows) {
    if (row.cells.size() != cols.names.size())
      fail(row.at, "", "has " + std::to_string(row.cells.size()) + " cells, the header " +
                           std::to_string(cols.names.size()) +
                           (row.cells.size() > cols.names.size()
                                ? " (quotes are not read: a comma inside a quoted cell splits it; name the material "
                                  "without commas)"
                                : ""));
    const RowReader r{cols, row};
    read_q_measure(r, d);
    TriaxialTest& t = test_of(r, d, tests);
    if (d.curves)
      read_curve_row(r, t);
    else
      read_summary_row(r, t);
  }
  if (d.tests.empty()) throw DataError(path + ": no data rows");
  if (d.curves)
    for (TriaxialTest& t : d.tests) {
      if (t.eps_a.size() < kMinCurveRows)
        throw DataError(path + ": " + describe_test(t) + ": " + std::to_string(t.eps_a.size()) + " row" +
                        (t.eps_a.size() == 1 ? "" : "s") + " (allowed: at least " + std::to_string(kMinCurveRows) +
                        " rows of eps_a and q per test: a curve; give one row per test in a summary file, with "
                        "q_peak_<unit> and no eps_a column)");
      if (t.eps_a.size() > kMaxCurveRows)
        throw DataError(path + ": " + describe_test(t) + ": " + std::to_string(t.eps_a.size()) + " rows (allowed: at most " +
                        std::to_string(kMaxCurveRows) + " per test: a curve shows no more at a million rows than at "
                        "ten thousand, and costs minutes to read; thin it, e.g. every " +
                        std::to_string((t.eps_a.size() + kMaxCurveRows - 1) / kMaxCurveRows * 10) + "th row)");
      summarise(t);
    }
  for (const TriaxialTest& t : d.tests) check_plausible(path, t, d.curves);
  note_replicates(d);
  if (!d.q_measure_given)
    d.notes.push_back(path + ": no q_measure column: q taken as fixed_area (platen force over the cross-section "
                             "after consolidation, as Tang et al. 2025 report it)");
  return d;
}

}  // namespace dem
