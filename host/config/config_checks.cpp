/// Rules a config is checked against beyond its keys' ranges: the time step, the memory a run needs, the text
/// toml++ may see. Declared in config.hpp (config_checks.hpp for the two used only by the reader).
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

#include "host/config/config.hpp"
#include "host/config/config_checks.hpp"

#include "host/config/model_keys.hpp"
#include "host/util/text_format.hpp"

namespace dem {

Real time_step(const SolverConfig& solver, Real critical, const std::string& path) {
  if (solver.dt > critical || (solver.dt > 0 && solver.dt < kMinDtFraction * critical)) {
    std::ostringstream m;
    m << path << ": [solver] dt_s: " << solver.dt << " s is " << (solver.dt > critical ? "above" : "far below")
      << " the critical time step " << critical << " s of these balls and contact laws (allowed: ["
      << kMinDtFraction * critical << ", " << critical << "]; leave dt_s out to use dt_safety x critical)";
    throw ConfigError(m.str());
  }
  return solver.dt > 0 ? solver.dt : solver.dt_safety * critical;
}

double run_memory_bytes(long balls) { return kBytesPerBall * static_cast<double>(balls); }

double available_memory() {
  std::ifstream in("/proc/meminfo");
  std::string key;
  double kb = 0;
  std::string unit;
  while (in >> key >> kb >> unit)
    if (key == "MemAvailable:") return kb * 1024;
  return 0;
}

/// What a run of the periodic cell could not survive, refused where `check` would otherwise say OK (issue 87): balls
/// so few for the box that it is nearly empty (2 um balls in a 14.5 mm box: a gas that never packs), and a linear
/// law so soft that the cell pressure overlaps its contacts by more than a tenth of a diameter (the overlap of a
/// contact loaded by sigma3 d^2 is about sigma3 / emod of a diameter; emod_Pa = 0.1 under 100 kPa planned "a run of
/// 1 steps" and stopped at a negative box).
void check_cell_physics(const Config& c) {
  if (!c.has_periodic) return;
  const Real volume = c.box.size[0] * c.box.size[1] * c.box.size[2];
  const Real d = c.particles.diameter;
  const Real solid = static_cast<Real>(c.particles.count) * M_PI / 6 * d * d * d / volume;
  if (solid < kMinSolidFraction)
    throw ConfigError(c.path + ": [box] size_mm: " + std::to_string(c.particles.count) + " balls of " +
                      fmt("%g mm", 1e3 * d) + " fill " + fmt("%.2g", solid) + " of the box; a cell packs from at " +
                      fmt("least %g", kMinSolidFraction) + " (allowed: a box of at most " +
                      fmt("%.4g mm a side", 1e3 * std::cbrt(static_cast<Real>(c.particles.count) * M_PI / 6 * d * d * d /
                                                               kMinSolidFraction)) +
                      " for these balls, or more or larger balls: [particles] count, diameter_mm)");
  if (own_key_of(model_key("emod_Pa"), kContactLawNames[c.ball.law]) &&
      c.ball.emod < kMinStiffnessOverPressure * c.periodic.triax.sigma3)
    throw ConfigError(c.path + ": [material] emod_Pa: " + fmt("%g Pa", c.ball.emod) + " under sigma3 = " +
                      fmt("%g kPa", 1e-3 * c.periodic.triax.sigma3) + " overlaps the contacts by about " +
                      fmt("%.3g", c.periodic.triax.sigma3 / c.ball.emod) + " of a diameter (allowed: emod_Pa at least " +
                      fmt("%g", kMinStiffnessOverPressure) + " x sigma3, " +
                      fmt("%g Pa", kMinStiffnessOverPressure * c.periodic.triax.sigma3) + ")");
}

namespace {
/// toml++ asks whether what follows a backslash in a basic string is whitespace (a multi-line string's
/// line-ending backslash), and then of each character up to the next that is not: the first of those must be
/// ASCII, for the same undefined behaviour as outside strings. TOML never needs one there: a backslash escapes
/// only ASCII letters, quotes and itself, and a line-ending backslash trims spaces, tabs and line breaks.
void check_after_backslash(const std::string& text, std::size_t k, bool multi, const std::string& path) {
  std::size_t j = k + 1;
  while (j < text.size() &&
         (text[j] == ' ' || text[j] == '\t' || (multi && (text[j] == '\r' || text[j] == '\n'))))
    ++j;
  if (j >= text.size() || static_cast<unsigned char>(text[j]) < 0x80) return;
  long line = 1, col = 1;
  for (std::size_t i = 0; i < j; ++i) text[i] == '\n' ? (++line, col = 1) : ++col;
  throw ConfigError(path + ":" + std::to_string(line) + ":" + std::to_string(col) +
                    ": a non-ASCII character after a backslash in a string (escape it as \\uXXXX, or begin the "
                    "line after a line-ending backslash with an ASCII character)");
}
}  // namespace

/// Refuses a byte outside ASCII anywhere but in a string or a comment. Keys, numbers and table names are ASCII
/// in TOML; the toml++ of Debian 12 (3.3.0) reaches __builtin_unreachable (undefined behaviour) whenever it asks
/// whether such a character is whitespace, for all of U+00A1-U+0499, U+2FCE-U+33C7 and U+FB26-U+FEFE but a few
/// (is_non_ascii_horizontal_whitespace), so they must not get to it outside strings (found by tests/fuzz/fuzz_config).
/// Where strings are is decided as toml++ reads the text: a quote opens one only where a string may begin (at
/// the start of a line, after '=', ',', '{', an opening '[', or a dotted key's '.'), and a bare value (a
/// number, a boolean, a date, or junk such as 200''[''' followed by more) runs to a blank, ',', ']', '}', '#' or
/// the line's end, quotes and brackets included, because toml++ reads it so before it refuses it.
void check_ascii_outside_strings(const std::string& text, const std::string& path) {
  if (text.rfind("\xFF\xFE", 0) == 0 || text.rfind("\xFE\xFF", 0) == 0)
    throw ConfigError(path + ":1:1: UTF-16 text (TOML is UTF-8): save the file as UTF-8");
  long line = 1, col = 0;
  bool may_begin = true;  // a string, a value or a key may begin here
  bool in_key = true;     // a key is being read: a '.' joins the parts of a dotted key, and no value is bare
  bool bare = false;      // inside a bare value
  std::string open;       // the arrays ('[') and inline tables ('{') open here, innermost last
  for (std::size_t k = 0; k < text.size(); ++k, ++col) {
    const char c = text[k];
    if (c == '\n') {
      ++line, col = -1, may_begin = true, in_key = open.empty(), bare = false;
    } else if (c == ' ' || c == '\t' || c == '\r') {
      bare = false;
    } else if (c == '#') {  // a comment, to the end of the line
      while (k + 1 < text.size() && text[k + 1] != '\n') ++k, ++col;
    } else if (static_cast<unsigned char>(c) >= 0x80) {
      throw ConfigError(path + ":" + std::to_string(line) + ":" + std::to_string(col + 1) +
                        ": a non-ASCII character outside a string or a comment (keys, numbers and table names are "
                        "ASCII: write sigma3_kPa, not \u03c3)");
    } else if (bare && c != ',' && c != ']' && c != '}') {
      continue;
    } else if ((c == '"' || c == '\'') && may_begin) {
      const bool multi = text.compare(k, 3, std::string(3, c)) == 0;
      const std::string close = multi ? std::string(3, c) : std::string(1, c);
      k += close.size(), col += static_cast<long>(close.size());
      for (; k < text.size() && text.compare(k, close.size(), close) != 0; ++k, ++col) {
        if (c == '"' && text[k] == '\\') {
          check_after_backslash(text, k, multi, path);
          ++k, ++col;  // an escape: the next character is not the end
        }
        if (k < text.size() && text[k] == '\n') {
          if (!multi) break;  // an unterminated string: toml++ reports it
          ++line, col = -1;
        }
      }
      if (k < text.size() && text[k] != '\n') {
        k += close.size() - 1, col += static_cast<long>(close.size()) - 1, may_begin = false;
      } else if (k < text.size()) {
        ++line, col = -1, may_begin = true, in_key = open.empty();
      }
    } else {
      bare = false;
      const bool value_begins = !in_key && may_begin;
      if (c == '=') {
        in_key = false, may_begin = true;
      } else if (c == ',') {
        in_key = !open.empty() && open.back() == '{', may_begin = true;  // an inline table's next key
      } else if (c == '{' && value_begins) {
        open += c, in_key = true;
      } else if (c == '[') {
        if (value_begins) open += c;  // where a value begins, an array; at a line's start, a table's name
      } else if (c == '.' && in_key) {
        may_begin = true;
      } else if ((c == ']' || c == '}') && !open.empty() && open.back() == (c == ']' ? '[' : '{')) {
        open.pop_back(), may_begin = false;
      } else {
        bare = value_begins && c != ']' && c != '}';  // a value that is not a string, an array or a table
        may_begin = false;
      }
    }
  }
}

void check_records(const std::string& path, const char* table, const char* key, double every, const char* end_key,
                   double end) {
  if (every <= end / kMinRecords) return;
  throw ConfigError(path + ": [" + table + "] " + key + ": " + fmt("%g", 100 * every) + "% leaves " +
                    std::to_string(static_cast<long>(end / every)) + " records to the end at " + fmt("%g", 100 * end) +
                    "% (allowed: at most " + end_key + " / " + std::to_string(kMinRecords) + " = " +
                    fmt("%g", 100 * end / kMinRecords) + "%)");
}

}  // namespace dem
