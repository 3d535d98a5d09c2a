/// Rules a config is checked against beyond its keys' ranges: the time step, the memory a run needs, the text
/// toml++ may see. Declared in config.hpp (config_checks.hpp for the two used only by the reader).
#include <fstream>
#include <sstream>
#include <string>

#include "config.hpp"
#include "config_checks.hpp"

namespace dem {

Real time_step(const SolverConfig& solver, Real critical, const std::string& path) {
  if (solver.dt > critical) {
    std::ostringstream m;
    m << path << ": [solver] dt_s: " << solver.dt << " s is above the critical time step " << critical
      << " s of these balls and contact laws (allowed: (0, " << critical
      << "]; leave dt_s out to use dt_safety x critical)";
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

/// Refuses a byte outside ASCII anywhere but in a string or a comment. Keys, numbers and table names are ASCII
/// in TOML; the toml++ of Debian 12 (3.3.0) reaches __builtin_unreachable (undefined behaviour) on many such
/// characters there, e.g. U+0409 or U+FE7F, so they must not get to it (found by tests/fuzz/fuzz_config).
/// A quote opens a string only where TOML lets a string begin (after '=', '[', ',', '{', a key's '.', or at
/// the start of a line): toml++ reads a bare value such as 200''''' to its end before it refuses it, so a
/// quote inside one must not hide what follows from this check.
void check_ascii_outside_strings(const std::string& text, const std::string& path) {
  long line = 1, col = 0;
  char before = '\n';  // the last character outside strings and comments, blanks skipped
  bool in_key = true;  // no '=' yet on this line: a '.' joins the parts of a dotted key
  for (std::size_t k = 0; k < text.size(); ++k, ++col) {
    const char c = text[k];
    const bool string_may_begin = before == '\n' || before == '=' || before == '[' || before == ',' ||
                                  before == '{' || (before == '.' && in_key);
    if (c == '\n') {
      ++line, col = -1, before = '\n', in_key = true;
    } else if (c == ' ' || c == '\t' || c == '\r') {
      continue;
    } else if (c == '#') {  // a comment, to the end of the line
      while (k + 1 < text.size() && text[k + 1] != '\n') ++k, ++col;
    } else if ((c == '"' || c == '\'') && string_may_begin) {
      const bool multi = text.compare(k, 3, std::string(3, c)) == 0;
      const std::string close = multi ? std::string(3, c) : std::string(1, c);
      k += close.size(), col += static_cast<long>(close.size());
      for (; k < text.size() && text.compare(k, close.size(), close) != 0; ++k, ++col) {
        if (c == '"' && text[k] == '\\') ++k, ++col;  // an escape: the next character is not the end
        if (k < text.size() && text[k] == '\n') {
          if (!multi) break;  // an unterminated string: toml++ reports it
          ++line, col = -1;
        }
      }
      if (k < text.size() && text[k] != '\n') {
        k += close.size() - 1, col += static_cast<long>(close.size()) - 1, before = c;
      } else if (k < text.size()) {
        ++line, col = -1, before = '\n', in_key = true;
      }
    } else if (static_cast<unsigned char>(c) >= 0x80) {
      throw ConfigError(path + ":" + std::to_string(line) + ":" + std::to_string(col + 1) +
                        ": a non-ASCII character outside a string or a comment (keys, numbers and table names are "
                        "ASCII: write sigma3_kPa, not \u03c3)");
    } else {
      if (c == '=') in_key = false;
      before = c;
    }
  }
}

}  // namespace dem
