/// `triaxdem synth` (host/cli/calibration_jobs.hpp): synthetic measured curves of the base config's model with a hidden
/// extension switched on, from specimens no calibration ensemble of that config uses.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string>

#include "host/fit/calibrate.hpp"
#include "host/cli/calibration_jobs.hpp"
#include "host/fit/diagnose.hpp"
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
  if (fs::exists(o.output) && !o.overwrite)
    throw std::invalid_argument("synth -o " + o.output + ": the file exists (--overwrite replaces it)");
  if (o.extension != "none") {
    const Extension& e = extension(o.extension);
    const FreeParam range = free_param(e.param);
    if (!std::isnan(o.strength) && !(o.strength >= range.shown * range.lo && o.strength <= range.shown * range.hi))
      throw std::invalid_argument("synth --strength " + fmt("%g", o.strength) + ": out of the range of " + e.param +
                                  " (allowed: [" + fmt("%g", range.shown * range.lo) + ", " +
                                  fmt("%g", range.shown * range.hi) + "])");
    const Real v = !std::isnan(o.strength) ? o.strength / range.shown  // given in the key's unit
                                           : draw_strength(e, o.seed);
    set_param(truth, e.param, v);
    comment += " (" + e.param + " = " + fmt("%.4g", range.shown * v) + ")";
  }
  const unsigned specimen = o.specimen_seed >= 0 ? static_cast<unsigned>(o.specimen_seed)
                                                 : base.run.seed + kForeignSeedOffset;
  comment += ", a specimen per test (packing seeds from " + std::to_string(specimen) + ", " +
             std::to_string(kGeneratorCellFactor) + " times the config's balls)";
  PeriodicLab lab(larger_cell(base, kGeneratorCellFactor), true, static_cast<int>(o.sigma3.size()), specimen);
  lab.set_progress("synth: the tests");
  const std::vector<TriaxialTest> tests = synthetic_tests(lab, truth, o.sigma3, o.material, o.seed);
  write_measured_curves(o.output, tests, comment);
  std::printf("synth: %s -> %s\n", comment.c_str(), o.output.c_str());
  return 0;
}

}  // namespace dem
