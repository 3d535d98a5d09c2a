#include "host/data/compression_data.hpp"

#include <cmath>
#include <map>
#include <sstream>
#include <stdexcept>

#include "host/data/measured.hpp"

namespace dem {

const char* path_name(CompressionPath path) { return path == CompressionPath::oedometer ? "oedometer" : "isotropic"; }

CompressionPath compression_path(const std::string& name) {
  if (name == "oedometer") return CompressionPath::oedometer;
  if (name == "isotropic") return CompressionPath::isotropic;
  throw std::invalid_argument("compression test '" + name + "': allowed: oedometer, isotropic");
}

std::string describe(const CompressionTest& t) {
  std::ostringstream s;
  s << t.material << " " << path_name(t.path) << " from " << t.sigma3 / 1e3 << " kPa";
  return s.str();
}

std::string compression_csv(const std::vector<CompressionTest>& tests) {
  bool k0 = !tests.empty();
  for (const CompressionTest& t : tests) k0 = k0 && t.k0.size() == t.stress.size();
  std::ostringstream s;
  s.precision(8);
  s << "material,test_type,sigma3_kPa,stress_kPa,strain_pct" << (k0 ? ",K0" : "") << "\n";
  for (const CompressionTest& t : tests)
    for (std::size_t k = 0; k < t.stress.size(); ++k) {
      s << t.material << "," << path_name(t.path) << "," << t.sigma3 / 1e3 << "," << t.stress[k] / 1e3 << ","
        << 100 * t.strain[k];
      if (k0) s << "," << t.k0[k];
      s << "\n";
    }
  return s.str();
}

namespace {

constexpr const char* kAllowed =
    "material, test_type, sigma3_<unit>, stress_<unit>, strain_<unit>, strain_sd_<unit>, K0, K0_sd";

/// The columns by quantity, with the factor of each to SI.
struct Header {
  std::map<std::string, std::size_t> index;
  std::vector<Real> scale;
  std::vector<std::string> names;
  bool has(const std::string& q) const { return index.count(q) > 0; }
};

Header read_header(const MeasuredTextTable& table) {
  Header h;
  h.names = table.header;
  for (const std::string& name : table.header) {
    std::string q = name;
    Real scale = 1;
    for (const char* prefix : {"sigma3_", "stress_", "strain_sd_", "strain_"}) {
      const std::string p = prefix;
      if (name.rfind(p, 0) != 0) continue;
      q = p.substr(0, p.size() - 1);
      scale = column_scale(table.header_at, name, q != "strain" && q != "strain_sd");
      break;
    }
    if (q == name && name != "material" && name != "test_type" && name != "K0" && name != "K0_sd")
      throw DataError(table.header_at, name, std::string("unknown column (allowed: ") + kAllowed + ")");
    if (!h.index.emplace(q, h.scale.size()).second) throw DataError(table.header_at, name, "column given twice");
    h.scale.push_back(scale);
  }
  for (const char* need : {"material", "test_type", "sigma3", "stress", "strain"})
    if (!h.has(need))
      throw DataError(table.header_at, "", std::string("missing column '") + need + "' (a compression file has " +
                                               kAllowed + ")");
  if (h.has("K0_sd") && !h.has("K0"))
    throw DataError(table.header_at, "K0_sd", "a standard deviation of K0, which the file does not give");
  return h;
}

/// A cell in SI, checked to lie in (low, high]; `what` says the allowed range in the error.
Real number(const Header& h, const MeasuredTextTable::Row& row, const std::string& q, Real low, Real high,
            const std::string& what) {
  const std::size_t c = h.index.at(q);
  const std::string& cell = row.cells[c];
  const std::optional<double> v = parse_number(cell);
  if (!v || !std::isfinite(*v)) throw DataError(row.at, h.names[c], "'" + cell + "' is not a number");
  const Real si = *v * h.scale[c];
  if (!(si > low && si <= high)) throw DataError(row.at, h.names[c], "'" + cell + "' is out of range (allowed: " +
                                                                         what + ")");
  return si;
}

}  // namespace

std::vector<CompressionTest> load_compression(const std::string& path) {
  const MeasuredTextTable table = read_csv_table(path);
  const Header h = read_header(table);
  std::vector<CompressionTest> tests;
  for (const MeasuredTextTable::Row& row : table.rows) {
    if (row.cells.size() != h.names.size())
      throw DataError(row.at, "", "has " + std::to_string(row.cells.size()) + " cells, the header " +
                                      std::to_string(h.names.size()));
    const std::string& material = row.cells[h.index.at("material")];
    if (material.empty()) throw DataError(row.at, "material", "empty (allowed: a material's name)");
    CompressionPath kind;
    try {
      kind = compression_path(row.cells[h.index.at("test_type")]);
    } catch (const std::invalid_argument& e) {
      throw DataError(row.at, "test_type", e.what());
    }
    const Real sigma3 = number(h, row, "sigma3", 0, 1e9, "0 < sigma3 <= 1 GPa");
    CompressionTest* t = nullptr;
    for (CompressionTest& x : tests)
      if (x.material == material && x.path == kind && x.sigma3 == sigma3) t = &x;
    if (!t) {
      tests.push_back(CompressionTest{material, kind, sigma3, {}, {}, {}, {}, {}});
      t = &tests.back();
    }
    t->stress.push_back(number(h, row, "stress", 0, 1e9, "0 < stress <= 1 GPa"));
    t->strain.push_back(number(h, row, "strain", -kMaxStrain, kMaxStrain, "|strain| < 100%"));
    if (h.has("strain_sd")) t->strain_sd.push_back(number(h, row, "strain_sd", 0, kMaxStrain, "0 < sd < 100%"));
    if (h.has("K0")) {
      if (kind != CompressionPath::oedometer)
        throw DataError(row.at, "K0", "an isotropic test has no K0 (allowed: K0 in a file of oedometers only)");
      t->k0.push_back(number(h, row, "K0", 0, 10, "0 < K0 <= 10"));
      if (h.has("K0_sd")) t->k0_sd.push_back(number(h, row, "K0_sd", 0, 10, "0 < K0_sd <= 10"));
    }
  }
  if (tests.empty()) throw DataError(path, "", "no rows (a compression file needs at least one increment)");
  return tests;
}

}  // namespace dem
