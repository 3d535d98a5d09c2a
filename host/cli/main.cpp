/// triaxdem command line.
#include <CLI/CLI.hpp>
#include <Kokkos_Core.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <string>
#include <thread>

#include "host/fit/calibrate.hpp"
#include "host/cli/calibration_jobs.hpp"
#include "host/io/io_hdf5.hpp"
#include "host/data/measured.hpp"
#include "host/config/config.hpp"
#include "host/config/model_keys.hpp"
#include "host/cli/job.hpp"
#include "host/triax/micro_report.hpp"
#include "host/triax/periodic_triaxial.hpp"
#include "host/config/provenance.hpp"
#include "host/study/study.hpp"
#include "host/triax/triaxial.hpp"

namespace {

// Threads and processes beyond a few per core only slow a run down, and tens of thousands crash the OpenMP
// runtime (signal 11, no message): counts are refused above this many per core.
constexpr int kMaxPerCore = 8;

int machine_cores() { return static_cast<int>(std::max(1u, std::thread::hardware_concurrency())); }

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

/// OMP_NUM_THREADS as the OpenMP runtime would take it, checked before the runtime starts. Empty: fine.
std::string omp_threads_problem() {
  const char* env = std::getenv("OMP_NUM_THREADS");
  if (!env || !*env || count_fits(env, 1, true)) return "";
  return "OMP_NUM_THREADS=" + std::string(env) + " is no thread count for this machine (" + count_range(1) + ")";
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

/// The message for a first argument that names no command, or "" (CLI11 would say only that one is required).
std::string unknown_command(const CLI::App& app, const std::string& word) {
  std::string names;
  for (const CLI::App* c : app.get_subcommands([](const CLI::App*) { return true; })) {
    if (c->get_name() == word) return "";
    names += (names.empty() ? "" : ", ") + c->get_name();
  }
  return "'" + word + "' is no triaxdem command; the commands: " + names + " (triaxdem COMMAND --help for one)";
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"triaxdem: DEM laboratory for triaxial tests on granular materials"};
  app.set_version_flag("--version", dem::version_line());
  app.require_subcommand(1);
  std::string config_path, output;
  long steps = -1;

  auto* run = app.add_subcommand("run", "run the job a config describes");
  run->add_option("config", config_path, "TOML config file")->required()->check(CLI::ExistingFile);
  run->add_option("-o,--output", output, "output folder (overrides [run] output)");
  run->add_option("-n,--steps", steps, "number of steps (overrides [run] steps)")->check(CLI::NonNegativeNumber);
  bool resume = false;
  long stop_at = -1;
  run->add_flag("--resume", resume, "continue from the output folder's checkpoint.h5 to the step count");
  bool overwrite = false;
  const char* overwrite_help = "replace another run's outputs in the output folder (refused without it)";
  run->add_flag("--overwrite", overwrite, overwrite_help)->excludes("--resume");
  run->add_option("--stop-at-step", stop_at, "write a checkpoint after this step and stop (exit status 3)")
      ->check(CLI::NonNegativeNumber);

  auto* specimen = app.add_subcommand("specimen", "build the [specimen] of a config by multilayer compaction");
  specimen->add_option("config", config_path, "TOML config file")->required()->check(CLI::ExistingFile);
  specimen->add_option("-o,--output", output, "output folder (overrides [run] output)");
  specimen->add_flag("--overwrite", overwrite, overwrite_help);

  auto* triaxial = app.add_subcommand("triaxial", "specimen, membrane, consolidation and shear (drained triaxial test)");
  triaxial->add_option("config", config_path, "TOML config file")->required()->check(CLI::ExistingFile);
  triaxial->add_option("-o,--output", output, "output folder (overrides [run] output)");
  auto* triaxial_resume = triaxial->add_flag("--resume", resume, "continue from the output folder's checkpoint.h5");
  triaxial->add_flag("--overwrite", overwrite, overwrite_help)->excludes(triaxial_resume);
  triaxial->add_option("--stop-at-step", stop_at, "write a checkpoint after this step and stop (exit status 3)")
      ->check(CLI::NonNegativeNumber);

  auto* periodic = app.add_subcommand("periodic", "periodic-cell drained triaxial test (no platens, no membrane)");
  periodic->add_option("config", config_path, "TOML config file")->required()->check(CLI::ExistingFile);
  periodic->add_option("-o,--output", output, "output folder (overrides [run] output)");
  periodic->add_flag("--overwrite", overwrite, overwrite_help);

  std::vector<std::string> study_inputs;
  dem::StudyOptions study_opt;
  auto* study = app.add_subcommand("study", "run a set of triaxial cases and write one summary table and figure");
  study->add_option("configs", study_inputs, "config folders (every *.toml) or files")->required();
  study->add_option("-o,--output", study_opt.output, "output folder: summary, figure, one subfolder per case");
  study->add_option("-j,--jobs", study_opt.jobs, "cases run at once (default: one per two cores)")
      ->check(count_on_this_machine(0));
  study->add_option("-t,--threads", study_opt.threads, "OpenMP threads per case (default: the cores shared out)")
      ->check(count_on_this_machine(0));
  study->add_flag("--resume", study_opt.resume,
                  "keep the cases that finished (summary.csv), continue the triaxial cases from their checkpoints");
  study->add_option("--compare", study_opt.compare,
                    "measured data (docs/calibration.md: Measured data) whose q_peak goes beside each case's, matched by "
                    "[run] material and sigma3; repeat for several files")
      ->allow_extra_args(false)
      ->check(CLI::ExistingFile);

  std::string micro_source, micro_out;
  double micro_at = 0, micro_rve = 20;
  int micro_bins = 18;
  auto* micro = app.add_subcommand("micro", "micromechanics of a saved state (a run folder and a strain, or a snapshot)");
  micro->add_option("source", micro_source, "run folder or snap_<step>.h5")->required();
  micro->add_option("--at", micro_at, "axial strain of the saved state, % (with a run folder)");
  micro->add_option("--rve", micro_rve, "edge of the central cube, mm (default 20)");
  micro->add_option("--bins", micro_bins, "rose bins over 0-180 deg (default 18)")->check(CLI::Range(2, 3600));
  micro->add_option("-o,--output", micro_out, "output folder (default: the run folder or the snapshot's)");

  dem::CalibrationOptions cal;
  std::string free_list;
  auto add_calibration = [&](CLI::App* c) {
    c->add_option("data", cal.data, "measured-data CSV (docs/calibration.md: Measured data)")->required()
        ->check(CLI::ExistingFile);
    c->add_option("--config", config_path, "base config: a periodic cell ([box], [periodic], [material])")
        ->required()->check(CLI::ExistingFile);
    c->add_option("--free", free_list, "free parameters, comma-separated, of " + dem::free_key_names() +
                  " (default: the config's [calibrate] free, else mu_s,mu_r)");
    c->add_option("--material", cal.material, "only this material of the data");
    c->add_option("--reference", cal.reference, "CSV of reference values (material, then one column per parameter) "
                  "to set beside the calibrated ones")->check(CLI::ExistingFile);
    c->add_option("-o,--output", cal.output, "parent folder of the dated result folder (default out)");
    c->add_option("-j,--jobs", cal.jobs, "simulator runs at once, one thread each (default: one per core)")
        ->check(count_on_this_machine(1));
    c->add_option("--noise", cal.noise, "the data's noise: data (its standard-deviation columns, replicates, or its "
                  "curves' own scatter), lab (a lab's fixed scatter) or a lab noise file like "
                  "configs/calibration/lab_noise.toml; default data")
        ->check(CLI::IsMember({"data", "lab"}) | CLI::ExistingFile);
    c->add_option("--predict", cal.predict, "the test with a boundary to end with at the calibrated parameters: a "
                  "membrane test's config with [specimen] and [triaxial] (configs/small/ by default through "
                  "[calibrate] predict; configs/paper/ for full scale), walls (the config's cell between six walls: "
                  "the boundary's share of a walled test), or none");
    c->add_option("--resume", cal.resume, "continue in the result folder of an earlier run of this command on the "
                  "same data and config: the runs it stored are read, not run again")->check(CLI::ExistingDirectory);
    c->add_option("--reference-test", cal.reference_test, "what the calibration fits: periodic (the cell), walls "
                  "(the cell between six servo-controlled walls, measured at the walls) or two_fidelity (the cell "
                  "corrected by the --predict membrane test); default: [calibrate] reference_test")
        ->check(CLI::IsMember({"periodic", "walls", "two_fidelity"}));
  };
  auto* calibrate = app.add_subcommand("calibrate", "fit the free parameters to measured triaxial data");
  add_calibration(calibrate);
  auto* diagnose = app.add_subcommand("diagnose", "calibrate, then find which model extension explains the misfit");
  add_calibration(diagnose);
  dem::SynthOptions syn;
  std::vector<double> syn_kpa;
  auto* synth = app.add_subcommand("synth", "synthetic measured curves with a hidden model extension");
  synth->add_option("--config", config_path, "base config (periodic cell)")->required()->check(CLI::ExistingFile);
  synth->add_option("-o,--output", syn.output, "CSV to write")->required();
  synth->add_flag("--overwrite", syn.overwrite, "replace an existing output file (never the config)");
  synth->add_option("--extension", syn.extension, dem::extension_names() + " or none");
  synth->add_option("--strength", syn.strength, "the extension's parameter in its config unit (default: drawn from the seed)");
  synth->add_option("--seed", syn.seed, "noise and strength seed");
  synth->add_option("--specimen-seed", syn.specimen_seed, "packing seed of the specimen (default: the config's [run] "
                    "seed + 100000, a specimen no calibration ensemble of that config uses)");
  synth->add_option("--pressures", syn_kpa, "confining pressures, kPa (default 100 200 300)")->check(pressure_kpa());
  synth->add_option("--material", syn.material, "material name in the file");

  auto* check = app.add_subcommand("check", "validate a config and describe its job: balls, stages, time step, steps, a wall-time estimate");
  check->add_option("config", config_path, "TOML config file")->required()->check(CLI::ExistingFile);

  auto* info = app.add_subcommand("info", "print the Kokkos build in use");

  cal.jobs = machine_cores();
  if (argc > 1 && argv[1][0] != '-') {
    if (const std::string problem = unknown_command(app, argv[1]); !problem.empty()) {
      std::fprintf(stderr, "triaxdem: %s\n", problem.c_str());
      return 1;
    }
  }
  CLI11_PARSE(app, argc, argv);
  if (const std::string problem = omp_threads_problem(); !problem.empty()) {
    std::fprintf(stderr, "triaxdem: %s\n", problem.c_str());
    return 1;
  }
  // Parallel calibration runs are child processes of one thread each (PeriodicLab::set_jobs).
  if (calibrate->parsed() || diagnose->parsed()) dem::prepare_parallel_runs(cal.jobs);
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // progress reaches a log file as it happens
  if (study->parsed()) {  // the study only starts child processes: no Kokkos of its own
    try {
      const dem::io::FolderLock lock(study_opt.output);  // two studies into one folder would mix their cases
      return dem::study_job(study_inputs, study_opt, "/proc/self/exe");
    } catch (const std::exception& e) {
      std::fprintf(stderr, "triaxdem: %s\n", e.what());
      return 1;
    }
  }
  Kokkos::ScopeGuard guard(argc, argv);
  try {
    if (info->parsed()) {
      Kokkos::print_configuration(std::cout, false);
      return 0;
    }
    if (micro->parsed()) {
      namespace fs = std::filesystem;
      const std::string out = !micro_out.empty() ? micro_out
                              : fs::is_directory(micro_source) ? micro_source
                                                               : fs::path(micro_source).parent_path().string();
      return dem::micro_job(micro_source, micro_at, micro_rve, micro_bins, out.empty() ? "." : out);
    }
    dem::Config cfg = dem::load_config(config_path);
    if (!output.empty()) cfg.run.output = output;
    if (steps >= 0) cfg.run.steps = steps;
    if (check->parsed()) return dem::check_job(cfg);
    // Held until the job returns: a second run into the folder is refused while this one writes there.
    dem::io::FolderLock lock;
    if (run->parsed() || triaxial->parsed() || periodic->parsed() || specimen->parsed())
      lock = dem::io::claim_output_folder(cfg.run.output, resume, overwrite);
    if (specimen->parsed()) return dem::specimen_job(cfg);
    if (triaxial->parsed()) return dem::triaxial_job(cfg, resume, stop_at);
    if (periodic->parsed()) return dem::run_periodic_job(cfg);
    if (calibrate->parsed() || diagnose->parsed()) {
      if (!free_list.empty()) {
        cal.free.clear();
        std::stringstream in(free_list);
        for (std::string f; std::getline(in, f, ',');) cal.free.push_back(f);
      }
      return calibrate->parsed() ? dem::calibrate_job(cfg, cal) : dem::diagnose_job(cfg, cal);
    }
    if (synth->parsed()) {
      if (!syn_kpa.empty()) {
        syn.sigma3.clear();
        for (double k : syn_kpa) syn.sigma3.push_back(1e3 * k);
      }
      return dem::synth_job(cfg, syn);
    }
    return dem::run_job(cfg, resume, stop_at);
  } catch (const dem::DataError& e) {
    std::fprintf(stderr, "triaxdem: data error: %s\n", e.what());
    return 1;
  } catch (const dem::ConfigError& e) {
    std::fprintf(stderr, "triaxdem: config error: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "triaxdem: error: %s\n", e.what());
    return 1;
  }
}
