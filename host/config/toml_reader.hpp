#pragma once
/// The TOML layer under the config readers: a table reader that checks each key's type and range and refuses
/// unknown keys, with errors naming the file, the table and the key (ConfigError); a document whose top-level
/// entries must be known tables; and a canonical text of settings (for the specimen cache's key).
#include <toml++/toml.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "host/config/config.hpp"

namespace dem {

/// Reads one table, remembering which keys were used so that leftovers (typos) are refused.
class TableReader {
 public:
  TableReader(const std::string& file, const std::string& name, const toml::table* t)
      : file_(file), name_(name), t_(t) {}

  /// While set, every reader records the keys it is asked for ("table.key") with their kinds ("number",
  /// "integer", ...): how config_keys() lists every key without a second list to keep in step.
  static void log_keys(std::map<std::string, std::string>* log) { key_log_ = log; }

  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    std::ostringstream s;
    s << file_ << ": [" << name_ << "] " << key << ": " << what;
    throw ConfigError(s.str());
  }

  /// Whether the table holds the key (read or not).
  bool has(const std::string& key) const { return t_ && t_->contains(key); }
  /// A number in [lo, hi]; `scale` converts the file's unit to SI.
  void number(const std::string& key, Real& out, Real lo, Real hi, Real scale = 1, bool open_lo = false) {
    const toml::node* n = get(key, "number");
    if (n) out = checked_number(key, *n, lo, hi, open_lo) * scale;
  }
  /// Three numbers (x, y, z), each in [lo, hi], converted by `scale`.
  void number_triple(const std::string& key, std::array<Real, 3>& out, Real lo, Real hi, Real scale = 1,
                     bool open_lo = false) {
    const toml::node* n = get(key, "triple");
    if (!n) return;
    const toml::array* a = n->as_array();
    if (!a || a->size() != 3) fail(key, "expected an array of 3 numbers (x, y, z)");
    for (int d = 0; d < 3; ++d) out[d] = checked_number(key, (*a)[d], lo, hi, open_lo) * scale;
  }
  void integer(const std::string& key, long& out, long lo, long hi) {
    const toml::node* n = get(key, "integer");
    if (!n) return;
    auto v = n->value_exact<int64_t>();
    if (!v) fail(key, "expected an integer");
    if (*v < lo || *v > hi)
      fail(key, "value " + std::to_string(*v) + " out of range (allowed: [" + std::to_string(lo) + ", " +
                    std::to_string(hi) + "])");
    out = static_cast<long>(*v);
  }
  void boolean(const std::string& key, bool& out) {
    const toml::node* n = get(key, "boolean");
    if (!n) return;
    auto v = n->value_exact<bool>();
    if (!v) fail(key, "expected true or false");
    out = *v;
  }
  void string(const std::string& key, std::string& out, const std::set<std::string>& allowed = {}) {
    const toml::node* n = get(key, "string");
    if (!n) return;
    auto v = n->value_exact<std::string>();
    if (!v) fail(key, "expected a string");
    if (!allowed.empty() && !allowed.count(*v)) {
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      fail(key, "'" + *v + "' is not allowed (allowed: " + list + ")");
    }
    out = *v;
  }
  /// Whether the key holds the string `word`, which stands for `value`; any other string is refused with
  /// `word` among the allowed values, and a non-string is left to the key's other reader.
  bool word(const std::string& key, const std::string& word, long& out, long value) {
    const toml::node* n = get(key, "integer or word");
    if (!n || !n->is_string()) return false;
    const std::string given = *n->value_exact<std::string>();
    if (given != word) fail(key, "'" + given + "' is not allowed (allowed: \"" + word + "\" or a number)");
    out = value;
    return true;
  }
  /// An array of strings (at least one).
  void strings(const std::string& key, std::vector<std::string>& out) {
    const toml::node* n = get(key, "strings");
    if (!n) return;
    const toml::array* a = n->as_array();
    if (!a || a->empty()) fail(key, "expected a non-empty array of strings");
    out.clear();
    for (const toml::node& e : *a) {
      auto v = e.value_exact<std::string>();
      if (!v) fail(key, "expected a non-empty array of strings");
      out.push_back(*v);
    }
  }
  /// An array of numbers, each in [lo, hi], converted by `scale`.
  void numbers(const std::string& key, std::vector<Real>& out, Real lo, Real hi, Real scale) {
    const toml::node* n = get(key, "numbers");
    if (!n) return;
    const toml::array* a = n->as_array();
    if (!a) fail(key, "expected an array of numbers");
    out.clear();
    for (const toml::node& e : *a) {
      auto v = e.value<double>();
      if (!v || !(*v >= lo && *v <= hi)) {
        std::ostringstream r;
        r << "every value must be a number in [" << lo << ", " << hi << "]";
        fail(key, r.str());
      }
      out.push_back(*v * scale);
    }
  }
  /// Three booleans (x, y, z).
  void boolean_triple(const std::string& key, std::array<bool, 3>& out) {
    const toml::node* n = get(key, "booleans");
    if (!n) return;
    const toml::array* a = n->as_array();
    if (!a || a->size() != 3) fail(key, "expected [true|false, true|false, true|false]");
    for (int d = 0; d < 3; ++d) {
      auto v = (*a)[d].value_exact<bool>();
      if (!v) fail(key, "expected [true|false, true|false, true|false]");
      out[d] = *v;
    }
  }
  /// Refuses keys that were never read.
  void finish() const {
    if (!t_) return;
    for (const auto& [k, v] : *t_)
      if (!used_.count(std::string(k.str()))) fail(std::string(k.str()), "unknown key (check the spelling)");
  }

 private:
  static inline std::map<std::string, std::string>* key_log_ = nullptr;
  std::string file_, name_;
  const toml::table* t_;
  std::set<std::string> used_;
  const toml::node* get(const std::string& key, const char* kind) {
    if (key_log_) key_log_->emplace(name_ + "." + key, kind);
    if (!t_) return nullptr;
    used_.insert(key);
    return t_->get(key);
  }
  /// A finite number in [lo, hi] (an integer is taken as a number).
  double checked_number(const std::string& key, const toml::node& n, Real lo, Real hi, bool open_lo) const {
    auto d = n.value<double>();
    if (!d || n.is_boolean()) fail(key, "expected a number");
    const double v = *d;
    if (!std::isfinite(v) || v < lo || v > hi || (open_lo && v == lo)) {
      std::ostringstream r;
      r << "value " << v << " out of range (allowed: " << (open_lo ? "(" : "[") << lo << ", " << hi << "])";
      fail(key, r.str());
    }
    return v;
  }
};

/// The largest config or lab noise file read: the shipped ones are under 5 KiB.
constexpr std::size_t kMaxConfigBytes = 1 << 20;

/// The whole file, as bytes; ConfigError if it cannot be read or is larger than kMaxConfigBytes.
std::string file_text(const std::string& path);

/// The TOML document of `text`, whose top-level entries must be tables named in `tables`.
toml::table parse_tables(const std::string& text, const std::string& path, const std::vector<std::string>& tables);

/// The settings of a TOML node as text, equal for equal settings: tables in key order (toml++ keeps them sorted),
/// numbers exactly (%a). Not toml++'s formatter, which reaches undefined behaviour on NaN (UBSan, the gates).
void canonical_text(const toml::node& n, std::string& out);

}  // namespace dem
