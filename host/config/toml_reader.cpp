#include "host/config/toml_reader.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "host/config/config_checks.hpp"

namespace dem {

void canonical_text(const toml::node& n, std::string& out) {
  char buf[64];
  if (const toml::table* t = n.as_table()) {
    out += '{';
    for (const auto& [k, v] : *t) {
      out += std::string(k.str()) + '=';
      canonical_text(v, out);
      out += ';';
    }
    out += '}';
  } else if (const toml::array* a = n.as_array()) {
    out += '[';
    for (const toml::node& e : *a) {
      canonical_text(e, out);
      out += ',';
    }
    out += ']';
  } else if (n.is_number()) {  // by value: the reader takes 1 and 1.0 as the same setting
    std::snprintf(buf, sizeof buf, "%a", *n.value<double>());
    out += buf;
  } else if (auto b = n.value_exact<bool>()) {
    out += *b ? "true" : "false";
  } else if (auto s = n.value_exact<std::string>()) {
    out += '"' + *s + '"';
  } else {
    out += '?';  // dates and times: no key takes them, and the reader refuses them
  }
}

std::string file_text(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::exists(path, ec) && !std::filesystem::is_regular_file(path, ec))
    throw ConfigError(path + ": not a regular file (a config is a text file)");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ConfigError(path + ": cannot be read");
  // Read at most one byte past the cap: a device or a huge file (/dev/zero) is refused, not read into memory.
  std::string text(kMaxConfigBytes + 1, '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  text.resize(static_cast<std::size_t>(in.gcount()));
  if (text.size() > kMaxConfigBytes)
    throw ConfigError(path + ": larger than " + std::to_string(kMaxConfigBytes / 1024) +
                      " KiB (allowed: a config or noise file of at most that size)");
  // An editor's UTF-8 byte order mark is no part of the first key (it was refused as a non-ASCII character).
  if (text.rfind("\xEF\xBB\xBF", 0) == 0) text.erase(0, 3);
  return text;
}

toml::table parse_tables(const std::string& text, const std::string& path, const std::vector<std::string>& tables) {
  check_ascii_outside_strings(text, path);
  toml::table root;
  try {
    root = toml::parse(text, path);
  } catch (const toml::parse_error& e) {
    std::ostringstream s;
    s << path << ":" << e.source().begin.line << ":" << e.source().begin.column << ": " << e.description();
    throw ConfigError(s.str());
  }
  for (const auto& [k, v] : root) {
    if (std::find(tables.begin(), tables.end(), std::string(k.str())) == tables.end() || !v.is_table()) {
      std::string list;
      for (const std::string& t : tables) list += (list.empty() ? "" : ", ") + t;
      throw ConfigError(path + ": [" + std::string(k.str()) + "]: unknown table (allowed: " + list + ")");
    }
  }
  return root;
}

}  // namespace dem
