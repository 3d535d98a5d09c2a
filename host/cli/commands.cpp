/// The commands of the program (host/cli/commands.hpp): their options and what each runs.
#include <CLI/CLI.hpp>
#include <Kokkos_Core.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <string>

#include "host/cli/commands.hpp"
#include "host/util/busy_machine.hpp"
#include "host/study/calibration_jobs.hpp"
#include "host/config/config.hpp"
#include "host/config/model_keys.hpp"
#include "host/fit/diagnose.hpp"
#include "host/cli/job.hpp"
#include "host/study/study.hpp"
#include "host/util/ranks.hpp"
#include "host/util/text_format.hpp"

namespace dem::cli {

namespace {

// Threads and processes beyond a few per core only slow a run down, and tens of thousands crash the OpenMP
// runtime (signal 11, no message): counts are refused above this many per core.
constexpr int kMaxPerCore = 8;

std::string count_range(int lowest) {
  const int cores = machine_cores();
  return "allowed: " + std::string(lowest == 0 ? "0 for the default, " : "") + "1 to " +
         std::to_string(kMaxPerCore * cores) + ", " + std::to_string(kMaxPerCore) + " x this machine's " +
         std::to_string(cores) + " cores";
}

/// Whether `text` is an integer from `lowest` to kMaxPerCore x the cores; with `list`, the first of a
/// comma-separated list (OMP_NUM_THREADS gives one count per nesting level).
bool count_fits(const std::string& text, int lowest, bool list) {
  char* end = nullptr;
  const long v = std::strtol(text.c_str(), &end, 10);
  return end != text.c_str() && (*end == '\0' || (list && *end == ',')) && v >= lowest &&
         v <= kMaxPerCore * machine_cores();
}

/// A thread or process count: an integer from `lowest` (0: the default) to kMaxPerCore x the cores.
CLI::Validator count_on_this_machine(int lowest) {
  return CLI::Validator(
      [lowest](std::string& s) -> std::string {
        return count_fits(s, lowest, false) ? "" : s + " is no count for this machine (" + count_range(lowest) + ")";
      },
      "COUNT");
}

/// A confining pressure in kPa: a finite number above 0.
CLI::Validator pressure_kpa() {
  return CLI::Validator(
      [](std::string& s) -> std::string {
        char* end = nullptr;
        const double v = std::strtod(s.c_str(), &end);
        return end != s.c_str() && *end == '\0' && std::isfinite(v) && v > 0
                   ? ""
                   : s + " is no confining pressure (kPa, a number above 0)";
      },
      "KPA");
}

/// The config file and the output folder, which every command that runs one config takes.
void add_config_and_output(CLI::App* cmd, Args& a) {
  cmd->add_option("config", a.config_path, "TOML config file")->required()->check(CLI::ExistingFile);
  cmd->add_option("-o,--output", a.output, "output folder (overrides [run] output)");
}

const char* const kOverwriteHelp = "replace another run's outputs in the output folder (refused without it)";

void add_stop_at(CLI::App* cmd, Args& a) {
  cmd->add_option("--stop-at-step", a.stop_at, "write a checkpoint after this step and stop (exit status 3); "
                  "steps count from 1")
      ->check(CLI::Validator(
          [](std::string& s) -> std::string {
            // CLI11's PositiveNumber says "not in range 0 to 1.8e308" of 0 and "Could not convert" of 1.5.
            char* end = nullptr;
            const long long v = std::strtoll(s.c_str(), &end, 10);
            return end != s.c_str() && *end == '\0' && v >= 1 ? "" : s + " is no step (a whole number, 1 or more: steps "
                                                                           "count from 1)";
          },
          "STEP"));
}

void run_options(CLI::App* cmd, Args& a) {
  add_config_and_output(cmd, a);
  cmd->add_option("-n,--steps", a.steps, "number of steps (overrides [run] steps)")->check(CLI::NonNegativeNumber);
  cmd->add_flag("--resume", a.resume, "continue from the output folder's checkpoint.h5 to the step count");
  cmd->add_flag("--overwrite", a.overwrite, kOverwriteHelp)->excludes("--resume");
  add_stop_at(cmd, a);
}

void triaxial_options(CLI::App* cmd, Args& a) {
  add_config_and_output(cmd, a);
  auto* resume = cmd->add_flag("--resume", a.resume, "continue from the output folder's checkpoint.h5");
  cmd->add_flag("--overwrite", a.overwrite, kOverwriteHelp)->excludes(resume);
  add_stop_at(cmd, a);
}

/// specimen and periodic: a config, its output folder, --overwrite.
void one_config_options(CLI::App* cmd, Args& a) {
  add_config_and_output(cmd, a);
  cmd->add_flag("--overwrite", a.overwrite, kOverwriteHelp);
}

void compression_options(CLI::App* cmd, Args& a) {
  one_config_options(cmd, a);
  cmd->add_option("--test", a.compression_path, "oedometer (lateral strain zero, K0 recorded) or isotropic (every axis "
                  "to the mean stress); default oedometer")
      ->check(CLI::IsMember({"oedometer", "isotropic"}));
  cmd->add_option("--stresses", a.compression_kpa, "the increments' targets in kPa, loading and unloading in order: "
                  "the axial stress (oedometer) or the mean stress (isotropic); default 2, 4, 8, 4, 2 times [periodic] "
                  "sigma3_kPa")
      ->delimiter(',')
      ->check(CLI::PositiveNumber);
}

void study_options(CLI::App* cmd, Args& a) {
  cmd->add_option("configs", a.study_inputs, "config folders (every *.toml) or files")->required();
  cmd->add_option("-o,--output", a.study.output, "output folder: summary, figure, one subfolder per case");
  cmd->add_option("-j,--jobs", a.study.workers, "cases run at once (default: one per two cores)")
      ->check(count_on_this_machine(0));
  cmd->add_option("-t,--threads", a.study.threads, "OpenMP threads per case (default: the cores shared out)")
      ->check(count_on_this_machine(0));
  cmd->add_flag("--resume", a.study.resume,
                "keep the cases that finished (summary.csv), continue the triaxial cases from their checkpoints");
  cmd->add_option("--compare", a.study.compare,
                  "measured data (docs/calibration.md: Measured data) whose q_peak goes beside each case's, matched "
                  "by [run] material and sigma3; repeat for several files")
      ->allow_extra_args(false)
      ->check(CLI::ExistingFile);
}

void micro_options(CLI::App* cmd, Args& a) {
  cmd->add_option("source", a.micro_source, "run folder or snap_<step>.h5")->required();
  cmd->add_option("--at", a.micro_at, "axial strain of the saved state, % (with a run folder)");
  cmd->add_option("--rve", a.micro_rve, "edge of the central cube, mm (default 20)")->check(CLI::PositiveNumber);
  cmd->add_option("--bins", a.micro_bins, "rose bins over 0-180 deg (default 18)")->check(CLI::Range(2, 3600));
  cmd->add_option("-o,--output", a.micro_out, "output folder (default: the run folder or the snapshot's)");
  cmd->add_flag("--overwrite", a.overwrite, "replace the files of an earlier micro of the same state");
}

/// calibrate and diagnose: the same options.
void calibration_options(CLI::App* cmd, Args& a) {
  cmd->add_option("data", a.cal.data, "measured-data CSV (docs/calibration.md: Measured data)")->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--config", a.config_path, "base config: a periodic cell ([box], [periodic], [material])")
      ->required()->check(CLI::ExistingFile);
  cmd->add_option("--free", a.free_list, "free parameters, comma-separated, of " + dem::free_key_names() +
                  " (default: the config's [calibrate] free, else mu_s,mu_r)");
  cmd->add_option("--material", a.cal.material, "only this material of the data");
  cmd->add_option("--reference", a.cal.reference, "CSV of reference values (material, then one column per parameter) "
                  "to set beside the calibrated ones")->check(CLI::ExistingFile);
  cmd->add_option("-o,--output", a.cal.output, "parent folder of the dated result folder (default out)");
  cmd->add_option("-j,--jobs", a.cal.workers, "simulator runs at once, one thread each (default: one per core)")
      ->check(count_on_this_machine(1));
  cmd->add_option("--noise", a.cal.noise, "the data's noise: data (its standard-deviation columns, replicates, or "
                  "its curves' own scatter), lab (a lab's fixed scatter) or a lab noise file like "
                  "configs/calibration/lab_noise.toml; default data")
      ->check(CLI::IsMember({"data", "lab"}) | CLI::ExistingFile);
  cmd->add_option("--predict", a.cal.predict, "the test with a boundary to end with at the calibrated parameters: a "
                  "membrane test's config with [specimen] and [triaxial] (configs/small/ by default through "
                  "[calibrate] predict; configs/paper/ for full scale), walls (the config's cell between six walls: "
                  "the boundary's share of a walled test), or none");
  cmd->add_option("--resume", a.cal.resume, "continue in the result folder of an earlier run of this command on the "
                  "same data and config: the runs it stored are read, not run again")->check(CLI::ExistingDirectory);
  cmd->add_option("--reference-test", a.cal.reference_test, "what the calibration fits: periodic (the cell), walls "
                  "(the cell between six servo-controlled walls, measured at the walls) or two_fidelity (the cell "
                  "corrected by the --predict membrane test); default: [calibrate] reference_test")
      ->check(CLI::IsMember({"periodic", "walls", "two_fidelity"}));
  cmd->add_flag("--plan", a.cal.plan_only, "print the plan (each stage's runs, their balls and particle-steps, about "
                "how long on this machine) and stop before any packing");
  cmd->add_flag("--yes", a.cal.yes, "run a plan longer than 4 hours (without it such a job is refused, naming the "
                "setting that costs most)");
  cmd->add_option("--compression", a.cal.compression, "a CSV of oedometer or isotropic compression tests (a test_type "
                  "column; docs/calibration.md) fitted with the triaxial data of their material: the strain at each "
                  "load pins the contact stiffness")
      ->check(CLI::ExistingFile);
}

void calibrate_options(CLI::App* cmd, Args& a) {
  calibration_options(cmd, a);
  cmd->add_option("--hold-out", a.cal.hold_out_kPa, "a confining pressure (kPa) of the data whose tests the fit "
                  "leaves out and the prediction predicts: the transfer to a pressure it never saw")
      ->check(pressure_kpa());
}

void synth_options(CLI::App* cmd, Args& a) {
  cmd->add_option("--config", a.config_path, "base config (periodic cell)")->required()->check(CLI::ExistingFile);
  cmd->add_option("-o,--output", a.syn.output, "CSV to write")->required();
  cmd->add_flag("--overwrite", a.syn.overwrite, "replace an existing output file (never the config)");
  cmd->add_option("--extension", a.syn.extension, dem::extension_names() + " or none");
  cmd->add_option("--strength", a.syn.strength,
                  "the extension's parameter in its config unit (default: drawn from the seed)")
      ->check(CLI::Validator([](std::string& s) -> std::string {
        // nan parses as a double, and a NaN strength means "draw one": a given one must be a number.
        return std::isfinite(std::strtod(s.c_str(), nullptr)) ? "" : s + " is not a number";
      }, "NUMBER"));
  cmd->add_option("--seed", a.syn.seed, "noise and strength seed");
  cmd->add_option("--specimen-seed", a.syn.specimen_seed, "packing seed of the specimen (default: the config's "
                  "[run] seed + 100000, a specimen no calibration ensemble of that config uses)");
  cmd->add_option("--cell-factor", a.syn.cell_factor, "the data's specimens have this many times the config's balls "
                  "(default " + std::to_string(dem::kGeneratorCellFactor) + ": data of a larger specimen than the "
                  "calibration's cell; 1: of the cell's own size)")->check(CLI::Range(1, 64));
  cmd->add_option("--pressures", a.syn_kpa, "confining pressures, kPa (default 100 200 300)")->check(pressure_kpa());
  cmd->add_option("--material", a.syn.material, "material name in the file");
}

void check_options(CLI::App* cmd, Args& a) {
  cmd->add_option("config", a.config_path, "TOML config file")->required()->check(CLI::ExistingFile);
}

/// The config a command names, with the command line's overrides.
dem::Config config_of(const Args& a) {
  dem::Config cfg = dem::load_config(a.config_path);
  if (!a.output.empty()) cfg.run.output = a.output;
  if (a.steps >= 0) cfg.run.steps = a.steps;
  return cfg;
}

/// A command that writes one run's folder: the folder held until the job returns, so that a second run into it is
/// refused while this one writes there.
template <class Job>
int in_own_folder(const Args& a, Job job) {
  const dem::Config cfg = config_of(a);
  const dem::io::FolderLock lock = dem::io::claim_output_folder(cfg.run.output, a.resume, a.overwrite);
  return job(cfg);
}

/// The study's folder claimed by the leader alone, with every rank told whether it was refused, then checked to be
/// seen by every rank (each writes its cases there).
dem::io::FolderLock claim_for_all_ranks(const std::string& folder) {
  dem::io::FolderLock lock;
  std::string refused;
  if (dem::ranks::leader()) {
    try {
      lock = dem::io::FolderLock(folder);
    } catch (const std::exception& e) {
      refused = e.what();
    }
  }
  if (const std::string why = dem::ranks::agree(refused); !why.empty()) throw std::runtime_error(why);
  dem::ranks::check_shared_folder(folder);
  return lock;
}

int micro(Args& a) {
  namespace fs = std::filesystem;
  const std::string out = !a.micro_out.empty() ? a.micro_out
                          : fs::is_directory(a.micro_source) ? a.micro_source
                                                             : fs::path(a.micro_source).parent_path().string();
  return dem::micro_job(a.micro_source, a.micro_at, a.micro_rve, a.micro_bins, out.empty() ? "." : out, a.overwrite);
}

int calibration(Args& a, bool diagnose) {
  if (!a.free_list.empty()) a.cal.free = dem::split_fields(a.free_list);
  const dem::Config cfg = config_of(a);
  return diagnose ? dem::diagnose_job(cfg, a.cal) : dem::calibrate_job(cfg, a.cal);
}

int synth(Args& a) {
  if (!a.syn_kpa.empty()) {
    a.syn.sigma3.clear();
    for (double k : a.syn_kpa) a.syn.sigma3.push_back(1e3 * k);
  }
  return dem::synth_job(config_of(a), a.syn);
}

int study(Args& a) {
  // Two studies into one folder would mix their cases.
  const dem::io::FolderLock lock = claim_for_all_ranks(a.study.output);
  return dem::study_job(a.study_inputs, a.study, "/proc/self/exe");
}

}  // namespace

std::string omp_threads_problem() {
  const char* env = std::getenv("OMP_NUM_THREADS");
  if (!env || !*env || count_fits(env, 1, true)) return "";
  return "OMP_NUM_THREADS=" + std::string(env) + " is no thread count for this machine (" + count_range(1) + ")";
}

const std::vector<Command>& command_table() {
  static const std::vector<Command> table = {
    {"run", "run the job a config describes", run_options,
     [](Args& a) {
       return in_own_folder(a, [&](const dem::Config& c) { return dem::run_job(c, a.resume, a.stop_at); });
     }},
    {"specimen", "build the [specimen] of a config by multilayer compaction", one_config_options,
     [](Args& a) { return in_own_folder(a, dem::specimen_job); }},
    {"triaxial", "specimen, membrane, consolidation and shear (drained triaxial test)", triaxial_options,
     [](Args& a) {
       return in_own_folder(a, [&](const dem::Config& c) { return dem::triaxial_job(c, a.resume, a.stop_at); });
     }},
    {"periodic", "periodic-cell drained triaxial test (no platens, no membrane)", one_config_options,
     [](Args& a) { return in_own_folder(a, dem::run_periodic_job); }},
    {"compression", "oedometer or isotropic compression of a cell, loaded in increments", compression_options,
     [](Args& a) {
       return in_own_folder(
           a, [&](const dem::Config& c) { return dem::compression_job(c, a.compression_path, a.compression_kpa); });
     }},
    {"study", "run a set of triaxial cases and write one summary table and figure", study_options, study, true, false,
     false},
    {"micro", "micromechanics of a saved state (a run folder and a strain, or a snapshot)", micro_options, micro},
    {"calibrate", "fit the free parameters to measured triaxial data", calibrate_options,
     [](Args& a) { return calibration(a, false); }, true, true},
    {"diagnose", "calibrate, then find which model extension explains the misfit", calibration_options,
     [](Args& a) { return calibration(a, true); }, true, true},
    {"synth", "synthetic measured curves with a hidden model extension", synth_options, synth},
    {"check", "validate a config and describe its job: balls, stages, time step, steps, a wall-time estimate",
     check_options, [](Args& a) { return dem::check_job(config_of(a)); }},
    {"info", "print the Kokkos build in use", [](CLI::App*, Args&) {},
     [](Args&) {
       Kokkos::print_configuration(std::cout, false);
       return 0;
     }},
  };
  return table;
}

std::string over_ranks_names() {
  std::vector<std::string> names;
  for (const Command& c : command_table())
    if (c.over_ranks) names.push_back(c.name);
  std::string text;
  for (std::size_t k = 0; k < names.size(); ++k)
    text += (k == 0 ? "" : k + 1 == names.size() ? " and " : ", ") + names[k];
  return text;
}

}  // namespace dem::cli
