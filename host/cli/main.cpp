/// triaxdem command line.
#include <CLI/CLI.hpp>
#include <Kokkos_Core.hpp>

#include <algorithm>
#include <chrono>
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
#include "host/util/ranks.hpp"
#include "host/util/text_format.hpp"

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

/// Everything the command line sets, filled by CLI11.
struct Args {
  std::string config_path, output;
  long steps = -1;
  bool resume = false, overwrite = false;
  long stop_at = -1;
  std::vector<std::string> study_inputs;
  dem::StudyOptions study;
  std::string micro_source, micro_out;
  double micro_at = 0, micro_rve = 20;
  int micro_bins = 18;
  dem::CalibrationOptions cal;
  std::string free_list;
  dem::SynthOptions syn;
  std::vector<double> syn_kpa;
};

/// The commands, to ask which one was given.
struct Commands {
  CLI::App *run, *specimen, *triaxial, *periodic, *study, *micro, *calibrate, *diagnose, *synth, *check, *info;
};

/// The config file and the output folder, which every command that runs one config takes.
void add_config_and_output(CLI::App* cmd, Args& a) {
  cmd->add_option("config", a.config_path, "TOML config file")->required()->check(CLI::ExistingFile);
  cmd->add_option("-o,--output", a.output, "output folder (overrides [run] output)");
}

/// The commands that run one test or job from a config.
void add_test_commands(CLI::App& app, Args& a, Commands& c) {
  c.run = app.add_subcommand("run", "run the job a config describes");
  add_config_and_output(c.run, a);
  c.run->add_option("-n,--steps", a.steps, "number of steps (overrides [run] steps)")->check(CLI::NonNegativeNumber);
  c.run->add_flag("--resume", a.resume, "continue from the output folder's checkpoint.h5 to the step count");
  const char* overwrite_help = "replace another run's outputs in the output folder (refused without it)";
  c.run->add_flag("--overwrite", a.overwrite, overwrite_help)->excludes("--resume");
  c.run->add_option("--stop-at-step", a.stop_at, "write a checkpoint after this step and stop (exit status 3); "
                    "steps count from 1")
      ->check(CLI::PositiveNumber);

  c.specimen = app.add_subcommand("specimen", "build the [specimen] of a config by multilayer compaction");
  add_config_and_output(c.specimen, a);
  c.specimen->add_flag("--overwrite", a.overwrite, overwrite_help);

  c.triaxial = app.add_subcommand("triaxial", "specimen, membrane, consolidation and shear (drained triaxial test)");
  add_config_and_output(c.triaxial, a);
  auto* triaxial_resume = c.triaxial->add_flag("--resume", a.resume, "continue from the output folder's checkpoint.h5");
  c.triaxial->add_flag("--overwrite", a.overwrite, overwrite_help)->excludes(triaxial_resume);
  c.triaxial->add_option("--stop-at-step", a.stop_at, "write a checkpoint after this step and stop (exit status 3); "
                    "steps count from 1")
      ->check(CLI::PositiveNumber);

  c.periodic = app.add_subcommand("periodic", "periodic-cell drained triaxial test (no platens, no membrane)");
  add_config_and_output(c.periodic, a);
  c.periodic->add_flag("--overwrite", a.overwrite, overwrite_help);
}

/// The study and micro commands: a set of configs, and a saved state.
void add_study_commands(CLI::App& app, Args& a, Commands& c) {
  c.study = app.add_subcommand("study", "run a set of triaxial cases and write one summary table and figure");
  c.study->add_option("configs", a.study_inputs, "config folders (every *.toml) or files")->required();
  c.study->add_option("-o,--output", a.study.output, "output folder: summary, figure, one subfolder per case");
  c.study->add_option("-j,--jobs", a.study.workers, "cases run at once (default: one per two cores)")
      ->check(count_on_this_machine(0));
  c.study->add_option("-t,--threads", a.study.threads, "OpenMP threads per case (default: the cores shared out)")
      ->check(count_on_this_machine(0));
  c.study->add_flag("--resume", a.study.resume,
                  "keep the cases that finished (summary.csv), continue the triaxial cases from their checkpoints");
  c.study->add_option("--compare", a.study.compare,
                    "measured data (docs/calibration.md: Measured data) whose q_peak goes beside each case's, matched "
                    "by [run] material and sigma3; repeat for several files")
      ->allow_extra_args(false)
      ->check(CLI::ExistingFile);

  c.micro = app.add_subcommand("micro", "micromechanics of a saved state (a run folder and a strain, or a snapshot)");
  c.micro->add_option("source", a.micro_source, "run folder or snap_<step>.h5")->required();
  c.micro->add_option("--at", a.micro_at, "axial strain of the saved state, % (with a run folder)");
  c.micro->add_option("--rve", a.micro_rve, "edge of the central cube, mm (default 20)");
  c.micro->add_option("--bins", a.micro_bins, "rose bins over 0-180 deg (default 18)")->check(CLI::Range(2, 3600));
  c.micro->add_option("-o,--output", a.micro_out, "output folder (default: the run folder or the snapshot's)");
  c.micro->add_flag("--overwrite", a.overwrite, "replace the files of an earlier micro of the same state");
}

/// calibrate and diagnose (the same options) and synth.
void add_calibration_commands(CLI::App& app, Args& a, Commands& c) {
  auto add_calibration = [&](CLI::App* cmd) {
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
  };
  c.calibrate = app.add_subcommand("calibrate", "fit the free parameters to measured triaxial data");
  add_calibration(c.calibrate);
  c.calibrate->add_option("--hold-out", a.cal.hold_out_kPa, "a confining pressure (kPa) of the data whose tests the "
                          "fit leaves out and the prediction predicts: the transfer to a pressure it never saw");
  c.diagnose = app.add_subcommand("diagnose", "calibrate, then find which model extension explains the misfit");
  add_calibration(c.diagnose);
  c.synth = app.add_subcommand("synth", "synthetic measured curves with a hidden model extension");
  c.synth->add_option("--config", a.config_path, "base config (periodic cell)")->required()->check(CLI::ExistingFile);
  c.synth->add_option("-o,--output", a.syn.output, "CSV to write")->required();
  c.synth->add_flag("--overwrite", a.syn.overwrite, "replace an existing output file (never the config)");
  c.synth->add_option("--extension", a.syn.extension, dem::extension_names() + " or none");
  c.synth->add_option("--strength", a.syn.strength,
                      "the extension's parameter in its config unit (default: drawn from the seed)")
      ->check(CLI::Validator([](std::string& s) -> std::string {
        // nan parses as a double, and a NaN strength means "draw one": a given one must be a number.
        return std::isfinite(std::strtod(s.c_str(), nullptr)) ? "" : s + " is not a number";
      }, "NUMBER"));
  c.synth->add_option("--seed", a.syn.seed, "noise and strength seed");
  c.synth->add_option("--specimen-seed", a.syn.specimen_seed, "packing seed of the specimen (default: the config's "
                      "[run] seed + 100000, a specimen no calibration ensemble of that config uses)");
  c.synth->add_option("--pressures", a.syn_kpa, "confining pressures, kPa (default 100 200 300)")
      ->check(pressure_kpa());
  c.synth->add_option("--material", a.syn.material, "material name in the file");
}

/// check (a config and what its job would cost) and info (the Kokkos build).
void add_check_commands(CLI::App& app, Args& a, Commands& c) {
  c.check = app.add_subcommand("check", "validate a config and describe its job: balls, stages, time step, steps, "
                               "a wall-time estimate");
  c.check->add_option("config", a.config_path, "TOML config file")->required()->check(CLI::ExistingFile);
  c.info = app.add_subcommand("info", "print the Kokkos build in use");
}

/// The command given, once parsed, with Kokkos running.
int run_command(const Commands& c, Args& a) {
  if (c.info->parsed()) {
    Kokkos::print_configuration(std::cout, false);
    return 0;
  }
  if (c.micro->parsed()) {
    namespace fs = std::filesystem;
    const std::string out = !a.micro_out.empty() ? a.micro_out
                            : fs::is_directory(a.micro_source) ? a.micro_source
                                                               : fs::path(a.micro_source).parent_path().string();
    return dem::micro_job(a.micro_source, a.micro_at, a.micro_rve, a.micro_bins, out.empty() ? "." : out, a.overwrite);
  }
  dem::Config cfg = dem::load_config(a.config_path);
  if (!a.output.empty()) cfg.run.output = a.output;
  if (a.steps >= 0) cfg.run.steps = a.steps;
  if (c.check->parsed()) return dem::check_job(cfg);
  // Held until the job returns: a second run into the folder is refused while this one writes there.
  dem::io::FolderLock lock;
  if (c.run->parsed() || c.triaxial->parsed() || c.periodic->parsed() || c.specimen->parsed())
    lock = dem::io::claim_output_folder(cfg.run.output, a.resume, a.overwrite);
  if (c.specimen->parsed()) return dem::specimen_job(cfg);
  if (c.triaxial->parsed()) return dem::triaxial_job(cfg, a.resume, a.stop_at);
  if (c.periodic->parsed()) return dem::run_periodic_job(cfg);
  if (c.calibrate->parsed() || c.diagnose->parsed()) {
    if (!a.free_list.empty()) {
      a.cal.free = dem::split_fields(a.free_list);
    }
    return c.calibrate->parsed() ? dem::calibrate_job(cfg, a.cal) : dem::diagnose_job(cfg, a.cal);
  }
  if (c.synth->parsed()) {
    if (!a.syn_kpa.empty()) {
      a.syn.sigma3.clear();
      for (double k : a.syn_kpa) a.syn.sigma3.push_back(1e3 * k);
    }
    return dem::synth_job(cfg, a.syn);
  }
  return dem::run_job(cfg, a.resume, a.stop_at);
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

/// An error ends the program: on one rank as ever; spread over ranks, every rank stops, as a rank left alone would
/// wait for the others at the next pool. Every rank meets the same error on the same inputs: the leader says it,
/// and a shadow only where the leader has not ended the job first (an error of that rank's own).
int fail(const std::string& text) {
  if (!dem::ranks::spread()) {
    std::fprintf(stderr, "%s\n", text.c_str());
    return 1;
  }
  if (!dem::ranks::leader()) std::this_thread::sleep_for(std::chrono::seconds(3));
  dem::ranks::error_line(text);
  dem::ranks::abort_all(1);
}

}  // namespace

int main(int argc, char** argv) {
  try {
    dem::ranks::start(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "triaxdem: %s\n", e.what());
    return 1;
  }
  struct RanksEnd {
    ~RanksEnd() { dem::ranks::stop(); }
  } ranks_end;  // after Kokkos' own end below
  CLI::App app{"triaxdem: DEM laboratory for triaxial tests on granular materials"};
  app.set_version_flag("--version", dem::version_line());
  app.require_subcommand(1);
  Args a;
  Commands c{};
  add_test_commands(app, a, c);
  add_study_commands(app, a, c);
  add_calibration_commands(app, a, c);
  add_check_commands(app, a, c);
  a.cal.workers = machine_cores();
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
  if (dem::ranks::spread()) {
    if (!c.study->parsed() && !c.calibrate->parsed() && !c.diagnose->parsed())
      return fail("triaxdem: only study, calibrate and diagnose spread over MPI ranks (their runs are independent); "
                  "run one test without mpirun or srun");
    // A calibration's runs are child processes of one thread each, as on one machine (PeriodicLab::set_workers):
    // one rank per core. A study's cases are programs of their own, with the node's cores shared among its ranks.
    a.cal.workers = std::max(2, dem::ranks::size() - 1);
    if (!c.study->parsed()) dem::prepare_parallel_runs(a.cal.workers);
    dem::ranks::quiet_shadows();
  } else if (c.calibrate->parsed() || c.diagnose->parsed()) {
    // Parallel calibration runs are child processes of one thread each (PeriodicLab::set_workers).
    dem::prepare_parallel_runs(a.cal.workers);
  }
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // progress reaches a log file as it happens
  if (c.study->parsed()) {  // the study only starts child processes: no Kokkos of its own
    try {
      // Two studies into one folder would mix their cases.
      const dem::io::FolderLock lock = claim_for_all_ranks(a.study.output);
      return dem::study_job(a.study_inputs, a.study, "/proc/self/exe");
    } catch (const std::exception& e) {
      return fail(std::string("triaxdem: ") + e.what());
    }
  }
  Kokkos::ScopeGuard guard(argc, argv);
  try {
    return run_command(c, a);
  } catch (const dem::DataError& e) {
    return fail(std::string("triaxdem: data error: ") + e.what());
  } catch (const dem::ConfigError& e) {
    return fail(std::string("triaxdem: config error: ") + e.what());
  } catch (const std::exception& e) {
    return fail(std::string("triaxdem: error: ") + e.what());
  }
}
