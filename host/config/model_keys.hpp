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

struct ModelKey {
  const char* key;              ///< in [material] (or [periodic] for the membrane) and in --free
  Real ContactParams::*field;   ///< null: the periodic cell's membrane (Model::membrane, Pa)
  const char* unit;             ///< in words, for the docs and help ("-", "Pa", "r")
  Real lo, hi;                  ///< the config's allowed range, in the key's unit
  bool open_lo;                 ///< above lo, not at it
  Real scale;                   ///< SI value = key value x scale (1e3 for kPa)
  bool fit;                     ///< a calibration may free it
  Real fit_lo, fit_hi;          ///< SI: the range a calibration searches by default
  bool fit_log;                 ///< searched in equal ratios
  /// A model extension (0 = off): its name in the diagnosis ("" for a base parameter), the strengths it tries (SI),
  /// its signature in the data, and whether it turns off smoothly as the parameter goes to 0 (not so Hertz:
  /// delta_ref -> 0 is infinitely stiff, not linear).
  const char* extension;
  std::array<Real, 3> strengths;
  const char* signature;
  bool from_off;
  /// The diagnosis tries it (and synth makes data with it). An extension that names another code's data, which lack
  /// it, is a parameter to calibrate, not a verdict to offer.
  bool diagnosed = true;
  /// The contact law it belongs to (kContactLawNames); "" for every law's.
  const char* law = "";
};

/// The table: the base law first, then its extensions and the membrane.
const std::vector<ModelKey>& model_keys();
/// The row of a parameter a calibration may free; throws std::invalid_argument naming the allowed ones.
const ModelKey& model_key(const std::string& key);

/// The names in words, comma-separated, for help texts: the extensions the diagnosis tries ("hertz, roughness, ...")
/// or the keys a calibration may free.
std::string extension_names();
std::string free_key_names();

/// The keys of law `law` alone ("shear_modulus_Pa, poisson"), for messages.
std::string law_key_names(const std::string& law);

/// A key of another law than the pair's ([material] law) is refused: throws std::invalid_argument naming the key's
/// law and the keys the pair's law takes. Does nothing for a key of every law.
void require_law_of(const ModelKey& k, Real law);

}  // namespace dem
