#pragma once
/// Every parameter of the contact law and of the cell's membrane that a config sets, a calibration frees and a
/// diagnosis tries, described once: its key, unit, the config's allowed range, the range a calibration searches,
/// and for a model extension what the diagnosis needs (its name, the strengths it tries, its signature in words).
/// The config reader, `--free`, the diagnosis and the help all read this table, so a new parameter or extension is
/// one row here (and its physics in kernels/contact/contact_law.hpp).
#include <array>
#include <string>
#include <vector>

#include "kernels/core/contact_params.hpp"

namespace dem {

/// A row of the table, written with named fields: key(name, field, unit) and then what applies, e.g.
///   key("emod_Pa", &C::emod, "Pa").above(0, 1e13).searched_log(1e6, 1e10).of("rrlinear")
struct ModelKey {
  const char* key = "";                     ///< in [material] (or [periodic] for the membrane) and in --free
  Real ContactParams::*field = nullptr;     ///< null: the periodic cell's membrane (Model::membrane, Pa)
  const char* unit = "-";                   ///< in words, for the docs and help ("-", "Pa", "r")
  Real lo = 0, hi = 0;                      ///< the config's allowed range, in the key's unit
  bool open_lo = false;                     ///< above lo, not at it
  Real scale = 1;                           ///< SI value = key value x scale (1e3 for kPa)
  bool fit = false;                         ///< a calibration may free it
  Real fit_lo = 0, fit_hi = 0;              ///< SI: the range a calibration searches by default
  bool fit_log = false;                     ///< searched in equal ratios
  /// A model extension (0 = off): its name in the diagnosis ("" for a base parameter), the strengths it tries (SI),
  /// its signature in the data, and whether it turns off smoothly as the parameter goes to 0 (not so Hertz:
  /// delta_ref -> 0 is infinitely stiff, not linear).
  const char* extension = "";
  std::array<Real, 3> strengths{};
  const char* signature = "";
  bool from_off = true;
  /// The diagnosis tries it (and synth makes data with it). An extension that names another code's data, which lack
  /// it, is a parameter to calibrate, not a verdict to offer.
  bool diagnosed = true;
  /// The contact laws it belongs to (kContactLawNames, comma-separated: "rrlinear, rrlinear_kr"); "" for every law's.
  const char* law = "";
  /// The law's materials must give it: it has no default (hertz_mindlin's constants).
  bool required = false;

  /// Allowed in [lo, hi], or in (lo, hi] (above).
  ModelKey& in(Real l, Real h) { return lo = l, hi = h, open_lo = false, *this; }
  ModelKey& above(Real l, Real h) { return lo = l, hi = h, open_lo = true, *this; }
  /// The key's unit times s is SI (1e3 for kPa).
  ModelKey& times(Real s) { return scale = s, *this; }
  /// A calibration may free it, searching [l, h] (SI) by default, in equal steps or in equal ratios.
  ModelKey& searched(Real l, Real h) { return fit = true, fit_lo = l, fit_hi = h, fit_log = false, *this; }
  ModelKey& searched_log(Real l, Real h) { return fit = true, fit_lo = l, fit_hi = h, fit_log = true, *this; }
  /// A model extension the diagnosis names `name`, trying `tried` (SI), seen in the data as `seen`.
  ModelKey& extension_named(const char* name, std::array<Real, 3> tried, const char* seen) {
    return extension = name, strengths = tried, signature = seen, *this;
  }
  ModelKey& not_from_off() { return from_off = false, *this; }
  ModelKey& not_diagnosed() { return diagnosed = false, *this; }
  ModelKey& of(const char* law_names) { return law = law_names, *this; }
  ModelKey& needed() { return required = true, *this; }
};

/// A row's start: its key, field and unit.
inline ModelKey key(const char* name, Real ContactParams::*field, const char* unit) {
  ModelKey k;
  k.key = name, k.field = field, k.unit = unit;
  return k;
}

/// The table: the base law first, then its extensions and the membrane.
const std::vector<ModelKey>& model_keys();
/// The row of a parameter a calibration may free; throws std::invalid_argument naming the allowed ones.
const ModelKey& model_key(const std::string& key);

/// The names in words, comma-separated, for help texts: the extensions the diagnosis tries ("hertz, roughness, ...")
/// or the keys a calibration may free.
std::string extension_names();
std::string free_key_names();

/// A key's allowed range in words: "[0, 0.5]", "(0, 1e13] Pa".
std::string allowed_range(const ModelKey& k);
/// The keys of law `law` alone ("shear_modulus_Pa, poisson"), for messages.
std::string law_key_names(const std::string& law);

/// Whether law `law` takes a key of `laws` (a row's `law`: "" for every law's, or a comma-separated list).
bool law_takes(const std::string& laws, const std::string& law);
/// Whether `law` has the key as its own, not every law's (the keys that name a law's stiffness in a specimen's key).
bool own_key_of(const ModelKey& k, const std::string& law);

/// A key of another law than the pair's ([material] law) is refused: throws std::invalid_argument naming the key's
/// laws and the keys the pair's law takes. Does nothing for a key of every law.
void require_law_of(const ModelKey& k, ContactLawId law);

}  // namespace dem
