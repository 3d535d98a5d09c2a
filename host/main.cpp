/// triaxdem command line.
#include <CLI/CLI.hpp>
#include <Kokkos_Core.hpp>

#include <cstdio>
#include <iostream>

#include "host/config.hpp"
#include "host/job.hpp"
#include "host/periodic_triaxial.hpp"
#include "host/study.hpp"
#include "host/triaxial.hpp"

int main(int argc, char** argv) {
  CLI::App app{"triaxdem: DEM laboratory for triaxial tests on granular materials"};
  app.require_subcommand(1);
  std::string config_path, output;
  long steps = -1;

  auto* run = app.add_subcommand("run", "run the job a config describes");
  run->add_option("config", config_path, "TOML config file")->required()->check(CLI::ExistingFile);
  run->add_option("-o,--output", output, "output folder (overrides [run] output)");
  run->add_option("-n,--steps", steps, "number of steps (overrides [run] steps)")->check(CLI::NonNegativeNumber);

  auto* specimen = app.add_subcommand("specimen", "build the [specimen] of a config by multilayer compaction");
  specimen->add_option("config", config_path, "TOML config file")->required()->check(CLI::ExistingFile);
  specimen->add_option("-o,--output", output, "output folder (overrides [run] output)");

  auto* triaxial = app.add_subcommand("triaxial", "specimen, membrane, consolidation and shear (drained triaxial test)");
  triaxial->add_option("config", config_path, "TOML config file")->required()->check(CLI::ExistingFile);
  triaxial->add_option("-o,--output", output, "output folder (overrides [run] output)");

  auto* periodic = app.add_subcommand("periodic", "periodic-cell drained triaxial test (no platens, no membrane)");
  periodic->add_option("config", config_path, "TOML config file")->required()->check(CLI::ExistingFile);
  periodic->add_option("-o,--output", output, "output folder (overrides [run] output)");

  std::vector<std::string> study_inputs;
  dem::StudyOptions study_opt;
  auto* study = app.add_subcommand("study", "run a set of triaxial cases and write one summary table and figure");
  study->add_option("configs", study_inputs, "config folders (every *.toml) or files")->required();
  study->add_option("-o,--output", study_opt.output, "output folder: summary, figure, one subfolder per case");
  study->add_option("-j,--jobs", study_opt.jobs, "cases run at once (default: one per two cores)")
      ->check(CLI::NonNegativeNumber);
  study->add_option("-t,--threads", study_opt.threads, "OpenMP threads per case (default: the cores shared out)")
      ->check(CLI::NonNegativeNumber);

  auto* check = app.add_subcommand("check", "validate a config and print the derived time step");
  check->add_option("config", config_path, "TOML config file")->required()->check(CLI::ExistingFile);

  auto* info = app.add_subcommand("info", "print the Kokkos build in use");

  CLI11_PARSE(app, argc, argv);
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // progress reaches a log file as it happens
  if (study->parsed()) {  // the study only starts child processes: no Kokkos of its own
    try {
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
    dem::Config cfg = dem::load_config(config_path);
    if (!output.empty()) cfg.run.output = output;
    if (steps >= 0) cfg.run.steps = steps;
    if (check->parsed()) {
      dem::build_simulation(cfg, true);
      std::printf("%s: OK\n", config_path.c_str());
      return 0;
    }
    if (specimen->parsed()) return dem::specimen_job(cfg);
    if (triaxial->parsed()) return dem::triaxial_job(cfg);
    if (periodic->parsed()) return dem::run_periodic_job(cfg);
    return dem::run_job(cfg);
  } catch (const dem::ConfigError& e) {
    std::fprintf(stderr, "triaxdem: config error: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "triaxdem: error: %s\n", e.what());
    return 1;
  }
}
