/// `triaxdem synth` (host/study/calibration_jobs.hpp): synthetic measured curves of the base config's model with a hidden
/// extension switched on, from specimens no calibration ensemble of that config uses.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string>

#include "host/fit/calibrate.hpp"
#include "host/study/calibration_jobs.hpp"
#include "host/config/model_keys.hpp"
#include "host/fit/diagnose.hpp"
#include "host/lab/run_cost.hpp"
#include "host/util/folder_lock.hpp"
#include "host/util/progress.hpp"
#include "host/util/text_format.hpp"

namespace dem {

namespace fs = std::filesystem;

int synth_job(const Config& base, const SynthOptions& o) {
  Model truth = model_of(base);
  std::string comment = "synthetic data from " + base.path + ", seed " + std::to_string(o.seed) + ", extension " +
                        o.extension;
  // The output is refused before any run: never the config itself, another file only with --overwrite.
  std::error_code ec;
  if (fs::exists(o.output) && fs::equivalent(o.output, base.path, ec))
    throw std::invalid_argument("synth -o " + o.output + ": that is the config (--config); name another file");
  // Two synths started at once into one file both wrote it, the last one's kept: the second is refused here.
  const io::FolderLock claim = io::FolderLock::of_file(o.output);
  if (fs::exists(o.output) && !o.overwrite)
    throw std::invalid_argument("synth -o " + o.output + ": the file exists (--overwrite replaces it)");
  if (o.extension == "none" && !std::isnan(o.strength))
    throw std::invalid_argument("synth --strength " + fmt("%g", o.strength) + ": --extension none has no strength "
                                "(name the extension it is for: " + extension_names() + ")");
  for (std::size_t i = 0; i < o.sigma3.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (std::fabs(o.sigma3[i] - o.sigma3[j]) < kReplicateTolerance * std::max(o.sigma3[i], o.sigma3[j]))
        throw std::invalid_argument("synth --pressures: " + fmt("%g", 1e-3 * o.sigma3[j]) + " and " +
                                    fmt("%g kPa", 1e-3 * o.sigma3[i]) + " are one pressure (within " +
                                    fmt("%g%%", 100 * kReplicateTolerance) + ", as calibrate reads them): one test a "
                                    "pressure, each given once");
  if (o.extension != "none") {
    const Extension& e = extension(o.extension);
    const FreeParam range = free_param(e.param, truth);  // an extension of another law than the base's is refused
    // A given strength may be any the config key takes (docs/config.md), not only what a diagnosis searches.
    const ModelKey& key = model_key(e.param);
    if (!std::isnan(o.strength) &&
        !((key.open_lo ? o.strength > key.lo : o.strength >= key.lo) && o.strength <= key.hi))
      throw std::invalid_argument("synth --strength " + fmt("%g", o.strength) + ": out of the range of " + e.param +
                                  " (allowed: " + (key.open_lo ? "(" : "[") + fmt("%g", key.lo) + ", " +
                                  fmt("%g", key.hi) + "], as [material] " + e.param + " takes it)");
    const Real v = !std::isnan(o.strength) ? o.strength / range.shown  // given in the key's unit
                                           : draw_strength(e, o.seed);
    set_param(truth, e.param, v);
    comment += " (" + e.param + " = " + fmt("%.4g", range.shown * v) + ")";
  }
  const int factor = o.cell_factor > 0 ? o.cell_factor : kGeneratorCellFactor;
  const unsigned specimen = o.specimen_seed >= 0 ? static_cast<unsigned>(o.specimen_seed)
                                                 : base.run.seed + kForeignSeedOffset;
  comment += ", a specimen per test (packing seeds from " + std::to_string(specimen) + ", " +
             std::to_string(factor) + " times the config's balls)";
  const Config cell = larger_cell(base, factor);
  // Said before the packings: a packing and a test per pressure one after another, at the engine's speed a probe
  // measures here.
  const CellCost cost = measure_cell_cost(cell);
  double seconds = 0;
  for (Real s : o.sigma3) seconds += cost.packing_seconds() + cost.run_seconds(s);
  std::printf("synth: %zu tests of %ld balls, a specimen each (packed first), to %s: about %s on this machine\n",
              o.sigma3.size(), cost.balls, o.output.c_str(), format_duration(seconds).c_str());
  std::fflush(stdout);
  PeriodicLab lab(cell, true, static_cast<int>(o.sigma3.size()), specimen);
  lab.set_progress("synth: the tests");
  const std::vector<TriaxialTest> tests = synthetic_tests(lab, truth, o.sigma3, o.material, o.seed);
  for (const TriaxialTest& t : tests)
    if (t.q.empty())
      throw std::runtime_error("synth: the test at " + fmt("%g kPa", 1e-3 * t.sigma3) + " stopped at a blow-up (" +
                               std::to_string(lab.failed_runs()) + " of " + std::to_string(tests.size()) + " tests did; " +
                               "nothing written): the contacts cannot carry that pressure; lower it, or stiffen them "
                               "([material] emod_Pa) or raise [solver] overlap_limit where the overlaps are physics");
  write_measured_curves(o.output, tests, comment);
  std::printf("synth: %s -> %s\n", comment.c_str(), o.output.c_str());
  return 0;
}

}  // namespace dem
