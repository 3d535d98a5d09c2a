#include "host/fit/calibrate.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "host/config/model_keys.hpp"

// The free parameters of a calibration (host/fit/calibrate.hpp): their ranges from the registry of model keys, their
// unit coordinates, and a model's value of each.

namespace dem {

Real FreeParam::value(Real u) const { return log ? lo * std::pow(hi / lo, u) : lo + u * (hi - lo); }
Real FreeParam::unit(Real v) const {
  return std::clamp(log ? std::log(v / lo) / std::log(hi / lo) : (v - lo) / (hi - lo), Real(0), Real(1));
}

namespace {
/// A parameter a calibration may free (host/config/model_keys.hpp), as the search sees it.
struct ParamSpec {
  FreeParam range;
  Real ContactParams::*field;  ///< null: the membrane
};
const std::vector<ParamSpec>& param_specs() {
  static const std::vector<ParamSpec> specs = [] {
    std::vector<ParamSpec> out;
    for (const ModelKey& k : model_keys())
      if (k.fit) out.push_back({{k.key, k.fit_lo, k.fit_hi, k.fit_log, 1 / k.scale}, k.field});
    return out;
  }();
  return specs;
}
const ParamSpec& spec(const std::string& name) {
  const ModelKey& k = model_key(name);  // refuses a name that is no free parameter, naming the allowed ones
  for (const ParamSpec& s : param_specs())
    if (s.range.name == k.key) return s;
  throw std::logic_error("calibrate: no search range for " + name);
}
}  // namespace

FreeParam free_param(const std::string& name) { return spec(name).range; }

FreeParam free_param(const std::string& name, const Model& base) {
  require_law_of(model_key(name), base.law.law);
  FreeParam f = free_param(name);
  const Real v = get_param(base, name);
  if ((name == "mu_s" || name == "emod_Pa" || name == "shear_modulus_Pa") && v > 0) {
    f.lo = v / 3;
    f.hi = 3 * v;
    f.log = true;
  } else if (name == "mu_r") {
    f.lo = 0;
    f.hi = std::max(4 * v, Real(0.05));
  }
  return f;
}

void set_param(Model& m, const std::string& name, Real v) {
  const ParamSpec& s = spec(name);
  if (s.field) m.law.*s.field = v;
  else m.membrane = v;
}

bool is_contact_param(const std::string& name) { return spec(name).field != nullptr; }

Real get_param(const Model& m, const std::string& name) {
  const ParamSpec& s = spec(name);
  return s.field ? m.law.*s.field : m.membrane;
}

bool recentre(FreeParam& f, Real v) {
  const FreeParam hard = free_param(f.name);
  const Real lo = std::max(f.log ? v * std::sqrt(f.lo / f.hi) : v - 0.5 * (f.hi - f.lo), hard.lo);
  const Real hi = std::min(f.log ? v * std::sqrt(f.hi / f.lo) : v + 0.5 * (f.hi - f.lo), hard.hi);
  const Real tol = 1e-3 * (f.hi - f.lo);
  // It moves only outwards, past the edge the value lies on; a range stopped by a hard limit stays.
  const bool moves = f.unit(v) > 0.5 ? hi > f.hi + tol : lo < f.lo - tol;
  if (!moves) return false;
  f.lo = lo;
  f.hi = hi;
  return true;
}

}  // namespace dem
