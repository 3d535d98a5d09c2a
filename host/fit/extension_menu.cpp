// The diagnosis's menu (host/fit/diagnose.hpp): the extensions model_keys marks as diagnosed, and those a base
// model's contact law takes.
#include <cstdio>
#include <stdexcept>

#include "host/config/model_keys.hpp"
#include "host/fit/diagnose.hpp"

namespace dem {

const std::vector<Extension>& extensions() {
  static const std::vector<Extension> list = [] {
    std::vector<Extension> out;
    for (const ModelKey& k : model_keys())
      if (*k.extension && k.diagnosed)
        out.push_back({k.extension, k.key, {k.strengths.begin(), k.strengths.end()}, k.signature, k.from_off, k.law});
    return out;
  }();
  return list;
}

const Extension& extension(const std::string& name) {
  std::string names;
  for (const Extension& e : extensions()) {
    if (e.name == name) return e;
    names += (names.empty() ? "" : ", ") + e.name;
  }
  throw std::invalid_argument("unknown extension '" + name + "' (allowed: " + names + ")");
}

namespace {
/// Whether extension e extends the base's law (the menu tries only those); says so where it does not.
bool extends_law_of(const Extension& e, const Model& base, bool verbose) {
  const std::string law = kContactLawNames[static_cast<int>(base.law.law)];
  if (law_takes(e.law, law)) return true;
  if (verbose)
    std::printf("diagnose: %-9s extends law %s, not this material's %s: not tried\n", e.name.c_str(), e.law.c_str(),
                law.c_str());
  return false;
}
}  // namespace

std::vector<Extension> extensions_of(const Model& base, bool verbose) {
  std::vector<Extension> out;
  for (const Extension& e : extensions())
    if (extends_law_of(e, base, verbose)) out.push_back(e);
  return out;
}

}  // namespace dem
