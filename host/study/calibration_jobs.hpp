#pragma once
/// The command-line jobs of calibration and diagnosis: `triaxdem calibrate`, `triaxdem diagnose` and
/// `triaxdem synth` (synthetic measured data with a hidden effect, for tests and studies).
#include <limits>
#include <string>
#include <vector>

#include "host/config/config.hpp"

namespace dem {

struct CalibrationOptions {
  std::string data;                       ///< measured-data CSV
  std::string output = "out";             ///< parent of the dated result folder
  std::vector<std::string> free;          ///< empty: the config's [calibrate] free
  std::string material;                   ///< empty: every material of the file
  int workers = 1;                           ///< simulator runs at once (PeriodicLab::set_workers)
  std::string reference;                  ///< optional reference values (load_reference) to set beside the fit
  std::string noise = "data";             ///< the data's noise: data, lab or a lab noise file
  /// The membrane test to predict with (host/fit/prediction.hpp): a config path, "none" for no prediction, or ""
  /// for the base config's [calibrate] predict.
  std::string predict;
  /// The reference test: "periodic", "two_fidelity", or "" for the base config's [calibrate] reference_test.
  std::string reference_test;
  /// A result folder of an earlier calibrate or diagnose of the same data to continue in: its stored runs
  /// (PeriodicLab::set_run_store) are read instead of run again. "": a new dated folder.
  std::string resume;
  bool plan_only = false;  ///< --plan: print the plan (what runs, about how long) and stop before any packing
  bool yes = false;        ///< --yes: run a plan longer than kPlanBoundSeconds
  /// --hold-out: the confining pressure (kPa) whose tests the calibration leaves out and the prediction predicts
  /// (NaN: none), a test of the transfer to a pressure the fit never saw.
  Real hold_out_kPa = std::numeric_limits<Real>::quiet_NaN();
  /// --compression: a file of compression tests (host/data/compression_data.hpp) fitted beside the triaxial tests of
  /// their material; "": none.
  std::string compression;
};

/// Calibrates each material of the data; writes calibrate_<date>/ under options.output. Returns 0.
int calibrate_job(const Config& base, const CalibrationOptions& o);

/// Diagnoses each material of the data; writes diagnose_<date>/ with diagnosis.md. Returns 0.
int diagnose_job(const Config& base, const CalibrationOptions& o);

struct SynthOptions {
  std::string output;                     ///< CSV to write
  std::string extension = "none";         ///< an extension's name (model_keys.hpp) or none
  /// The extension parameter in its key's unit, within its range (free_param); NaN: drawn from the seed.
  Real strength = std::numeric_limits<Real>::quiet_NaN();
  bool overwrite = false;                 ///< replace an existing output file (never the config)
  unsigned seed = 1;
  long specimen_seed = -1;                ///< packing seed; < 0: the config's seed + kForeignSeedOffset
  int cell_factor = 0;                    ///< the data's specimens have this many times the config's balls; 0:
                                          ///< kGeneratorCellFactor (host/fit/diagnose.hpp)
  std::vector<Real> sigma3{100e3, 200e3, 300e3};  ///< Pa
  std::string material = "synthetic";
};

/// Writes synthetic measured curves of the base config's model with the extension switched on. Returns 0.
int synth_job(const Config& base, const SynthOptions& o);

/// A new folder `<parent>/<prefix>_<YYYYmmdd-HHMMSS>` (a suffix -2, -3 ... if it exists): never an old one.
std::string new_dated_folder(const std::string& parent, const std::string& prefix);
/// The folder a resumed calibrate or diagnose (`kind`) continues in: one that a run of the same kind made. Throws
/// std::invalid_argument naming --resume otherwise.
std::string resumed_folder(const std::string& folder, const std::string& kind);
/// The parent folder of a resumed folder: where its run left the specimens it shares with others.
std::string resumed_parent(const std::string& folder);

}  // namespace dem
