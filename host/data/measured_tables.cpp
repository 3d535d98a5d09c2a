/// The text tables of measured data (host/data/measured.hpp): a CSV file's lines as cells, and reference parameter
/// values (a paper's own calibration, set beside a calibrated one).
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "host/data/measured.hpp"
#include "host/util/text_format.hpp"

namespace dem {

namespace {

/// Refuses a file that is no UTF-8 or ASCII text, by its first bytes: its raw bytes would otherwise be printed as a
/// column's name ("\xff\xfem", "\x89HDF: unknown column").
void check_is_text(const std::string& path, std::ifstream& f) {
  char head[8] = {};
  f.read(head, sizeof head);
  const std::string b(head, static_cast<std::size_t>(f.gcount()));
  f.clear();
  f.seekg(0);
  if (b.rfind("\x89HDF", 0) == 0)
    throw DataError(path + ": an HDF5 file under another name (allowed: HDF5 measured data named .h5 or .hdf5, "
                    "text as .csv): rename it to .h5");
  if (b.rfind("\xFF\xFE", 0) == 0 || b.rfind("\xFE\xFF", 0) == 0)
    throw DataError(path + ": UTF-16 text (allowed: UTF-8 or ASCII): save it as UTF-8, in a spreadsheet as "
                    "\"CSV UTF-8\"");
  if (b.find('\0') != std::string::npos)
    throw DataError(path + ": not text (a NUL byte in its first bytes; allowed: a CSV text file, or HDF5 named .h5)");
}

}  // namespace

std::optional<double> parse_number(const std::string& cell) {
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(cell.c_str(), &end);
  if (cell.empty() || end != cell.c_str() + cell.size() || errno != 0) return std::nullopt;
  return v;
}

MeasuredTextTable read_csv_table(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::exists(path, ec) && !std::filesystem::is_regular_file(path, ec))
    throw DataError(path + ": not a regular file (measured data are a CSV or HDF5 file)");
  std::ifstream f(path, std::ios::binary);
  if (!f) throw DataError(path + ": cannot be read");
  check_is_text(path, f);
  MeasuredTextTable t;
  std::string line;
  for (long n = 1; std::getline(f, line); ++n) {
    // A spreadsheet's UTF-8 byte order mark is no part of the first column's name.
    if (n == 1 && line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);
    const std::string s = trim(line);
    if (s.empty() || s[0] == '#') continue;
    if (t.header.empty() && t.header_at.empty()) {
      t.header = split_cells(s);
      t.header_at = path + ":" + std::to_string(n);
    } else {
      if (t.rows.size() == kMaxFileRows)
        throw DataError(path + ":" + std::to_string(n) + ": more than " + std::to_string(kMaxFileRows) +
                        " data rows (allowed: at most " + std::to_string(kMaxFileRows) + " in a file, " +
                        std::to_string(kMaxCurveRows) + " per test; thin the curves, e.g. every 10th row)");
      t.rows.push_back({path + ":" + std::to_string(n), split_cells(s)});
    }
  }
  return t;
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
    const std::vector<std::string> cells = split_cells(t);
    if (ref.parameters.empty()) {
      if (cells.empty() || cells[0] != "material") throw DataError(path + ":" + std::to_string(n), cells.empty() ? "" : cells[0], "the first column must be 'material'");
      if (cells.size() < 2) throw DataError(path + ":" + std::to_string(n), "", "no parameter columns");
      for (std::size_t c = 1; c < cells.size(); ++c) {
        try {
          known(cells[c]);
        } catch (const std::invalid_argument& e) {
          throw DataError(path + ":" + std::to_string(n), cells[c], e.what());
        }
        ref.parameters.push_back(cells[c]);
      }
      continue;
    }
    if (cells.size() != ref.parameters.size() + 1)
      throw DataError(path + ":" + std::to_string(n), "", "has " + std::to_string(cells.size()) + " cells, the header " +
                            std::to_string(ref.parameters.size() + 1));
    if (cells[0].empty()) throw DataError(path + ":" + std::to_string(n), "material", "empty");
    for (std::size_t c = 0; c < ref.parameters.size(); ++c) {
      const std::string& v = cells[c + 1];
      char* end = nullptr;
      const double x = std::strtod(v.c_str(), &end);
      if (v.empty() || end != v.c_str() + v.size() || !std::isfinite(x))
        throw DataError(path + ":" + std::to_string(n), ref.parameters[c], "'" + v + "' is not a number");
      ref.values[cells[0]][ref.parameters[c]] = x;
    }
  }
  if (ref.parameters.empty()) throw DataError(path + ": no header line");
  return ref;
}

}  // namespace dem
