#include "host/config/model_keys.hpp"

#include <cstring>
#include <sstream>
#include <stdexcept>

namespace dem {

const std::vector<ModelKey>& model_keys() {
  // Extension strengths span the physical range in equal ratios: Hertz reference overlaps of 0.1-1% of the radius
  // (the overlaps of E* = 1e8 Pa beads at 100-300 kPa); combined roughness 0.1-1% of the radius (1-10 um on 2 mm
  // beads; Table 2 gives Sq = 5-53 um, but over 1.3 mm areas that include the beads' waviness); 20-60% of the
  // friction lost by wear; a twisting cap of 5-20% of Rbar Fn (a quarter to all of a rough bead's mu_r); an adhesion
  // of 10-100 kPa (a pull-off force of 0.04-0.4 N on 2 mm beads, a tenth to all of the mean contact force at 100 kPa;
  // less is not shown by triaxial curves at 100-300 kPa); a membrane of 0.1-1 MPa over the specimen's radius (latex,
  // 1.4 MPa x 0.5 mm, on 1.4-7 mm; small cells). Calibration ranges stay inside the config's where a smaller range is
  // all a fit needs (roughness beyond 5% of the radius is no longer a surface's), and the membrane's reaches 3 MPa,
  // above any latex. Adhesion once named YADE's cohesionless linear data, taking up the two codes' difference; it is
  // diagnosed again since a name must beat a generic discrepancy of its size, an apparent cohesion among them
  // (host/fit/generic_discrepancy.hpp).
  using C = ContactParams;
  static const std::vector<ModelKey> keys = {
      key("mu_s", &C::mu_s, "-").in(0, 10).searched_log(0.02, 1.0),
      key("mu_r", &C::mu_r, "-").in(0, 10).searched(0.0, 0.2),
      key("emod_Pa", &C::emod, "Pa").above(0, 1e13).searched_log(1e6, 1e10).of("rrlinear, rrlinear_kr"),
      key("kratio", &C::kratio, "-").above(0, 1e3).searched(1.0, 4.0).of("rrlinear, rrlinear_kr"),
      key("shear_modulus_Pa", &C::shear_modulus, "Pa").above(0, 1e13).searched_log(1e6, 1e11).of("hertz_mindlin")
          .needed(),
      key("poisson", &C::poisson, "-").in(0, 0.5).of("hertz_mindlin").needed(),
      key("kr_ratio", &C::kr_ratio, "-").above(0, 100).searched_log(0.1, 10).of("rrlinear_kr").needed(),
      key("beta_n", &C::beta_n, "-").in(0, 1),
      key("hertz_overlap", &C::hertz_overlap, "r").in(0, 0.5).searched_log(3e-4, 0.03).of("rrlinear, rrlinear_kr")
          .extension_named("hertz", {1e-3, 3e-3, 1e-2},
                           "initial stiffness that grows faster with confinement than the linear contacts give")
          .not_from_off(),
      key("roughness", &C::roughness, "r").in(0, 0.1).searched_log(1e-4, 5e-2).of("rrlinear, rrlinear_kr")
          .extension_named("roughness", {1e-3, 3e-3, 1e-2},
                           "soft initial response, most at low confinement; peak and residual hardly change"),
      key("wear", &C::wear, "-").in(0, 0.99).searched(0.0, 0.9)
          .extension_named("wear", {0.2, 0.4, 0.6},
                           "a residual strength that falls below the peak more than sliding alone explains"),
      key("wear_slip", &C::wear_slip, "r").above(0, 10).searched_log(0.005, 0.5),
      key("twist", &C::twist, "-").in(0, 10).searched(0.0, 0.5)
          .extension_named("twist", {0.05, 0.1, 0.2},
                           "more strength and dilatancy at every confinement, as a larger mu_r gives; spin in the "
                           "shear band held back"),
      key("adhesion_kPa", &C::adhesion, "kPa").in(0, 1e4).times(1e3).searched(0.0, 3e5)
          .extension_named("adhesion", {1e4, 3e4, 1e5},
                           "more strength and a stiffer start at low confinement than friction gives: an apparent "
                           "cohesion"),
      key("membrane_kPa", nullptr, "kPa").in(0, 1e5).times(1e3).searched(0.0, 3e6)
          .extension_named("membrane", {1e5, 3e5, 1e6},
                           "extra strength late in the test as the specimen bulges, largest relative to low sigma3"),
  };
  return keys;
}

const ModelKey& model_key(const std::string& key) {
  for (const ModelKey& k : model_keys())
    if (k.fit && key == k.key) return k;
  throw std::invalid_argument("unknown free parameter '" + key + "' (allowed: " + free_key_names() + ")");
}

std::string extension_names() {
  std::string names;
  for (const ModelKey& k : model_keys())
    if (*k.extension && k.diagnosed) names += (names.empty() ? "" : ", ") + std::string(k.extension);
  return names;
}

std::string free_key_names() {
  std::string names;
  for (const ModelKey& k : model_keys())
    if (k.fit) names += (names.empty() ? "" : ", ") + std::string(k.key);
  return names;
}

std::string allowed_range(const ModelKey& k) {
  std::ostringstream s;
  s << (k.open_lo ? "(" : "[") << k.lo << ", " << k.hi << "]" << (std::string(k.unit) == "-" ? "" : " ") <<
      (std::string(k.unit) == "-" ? "" : k.unit);
  return s.str();
}

std::string law_key_names(const std::string& law) {
  std::string names;
  for (const ModelKey& k : model_keys())
    if (own_key_of(k, law)) names += (names.empty() ? "" : ", ") + std::string(k.key);
  return names;
}

bool law_takes(const std::string& laws, const std::string& law) {
  if (laws.empty()) return true;
  std::istringstream list(laws);
  std::string name;
  while (std::getline(list >> std::ws, name, ','))
    if (name == law) return true;
  return false;
}

bool own_key_of(const ModelKey& k, const std::string& law) { return *k.law && law_takes(k.law, law); }

void require_law_of(const ModelKey& k, ContactLawId law) {
  const std::string mine = kContactLawNames[law];
  if (law_takes(k.law, mine)) return;
  std::string owners;  // "law \"a\"" or "laws \"a\", \"b\""
  for (const char* name : kContactLawNames)
    if (own_key_of(k, name)) owners += (owners.empty() ? "\"" : ", \"") + std::string(name) + "\"";
  throw std::invalid_argument(std::string(k.key) + " belongs to law" + (std::strchr(k.law, ',') ? "s " : " ") + owners +
                              "; law = \"" + mine +
                              "\" takes " + law_key_names(mine) + " instead");
}

}  // namespace dem
