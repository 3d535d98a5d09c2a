/// triaxdem command line: the command given (host/cli/commands.hpp) run with the processes, ranks and Kokkos it needs.
#include <CLI/CLI.hpp>
#include <Kokkos_Core.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "host/cli/commands.hpp"
#include "host/config/config.hpp"
#include "host/config/provenance.hpp"
#include "host/data/measured.hpp"
#include "host/lab/periodic_lab.hpp"
#include "host/util/busy_machine.hpp"
#include "host/util/process_pool.hpp"
#include "host/util/ranks.hpp"
#include "kernels/core/types.hpp"

namespace {

using dem::cli::Command;

/// The message for a first argument that names no command, or "" (CLI11 would say only that one is required).
std::string unknown_command(const CLI::App& app, const std::string& word) {
  std::string names;
  for (const CLI::App* c : app.get_subcommands([](const CLI::App*) { return true; })) {
    if (c->get_name() == word) return "";
    names += (names.empty() ? "" : ", ") + c->get_name();
  }
  return "'" + word + "' is no triaxdem command; the commands: " + names + " (triaxdem COMMAND --help for one)";
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
  dem::cli::Args a;
  std::vector<CLI::App*> given;  // beside command_table()
  for (const Command& cmd : dem::cli::command_table()) {
    given.push_back(app.add_subcommand(cmd.name, cmd.help));
    cmd.options(given.back(), a);
  }
  a.cal.workers = dem::machine_cores();
  if (argc > 1 && argv[1][0] != '-') {
    if (const std::string problem = unknown_command(app, argv[1]); !problem.empty()) {
      std::fprintf(stderr, "triaxdem: %s\n", problem.c_str());
      return 1;
    }
  }
  CLI11_PARSE(app, argc, argv);
  const auto parsed = std::find_if(given.begin(), given.end(), [](CLI::App* c) { return c->parsed(); });
  const Command& cmd = dem::cli::command_table()[static_cast<std::size_t>(parsed - given.begin())];
  if (const std::string problem = dem::cli::omp_threads_problem(); !problem.empty()) {
    std::fprintf(stderr, "triaxdem: %s\n", problem.c_str());
    return 1;
  }
  if (dem::ranks::spread()) {
    if (!cmd.over_ranks)
      return fail("triaxdem: only " + dem::cli::over_ranks_names() + " spread over MPI ranks (their runs are "
                  "independent); run one test without mpirun or srun");
    // A calibration's runs are child processes of one thread each, as on one machine (PeriodicLab::set_workers):
    // one rank per core. A study's cases are programs of their own, with the node's cores shared among its ranks.
    a.cal.workers = std::max(2, dem::ranks::size() - 1);
    if (cmd.parallel_runs) dem::prepare_parallel_runs(a.cal.workers);
    dem::ranks::quiet_shadows();
  } else if (cmd.parallel_runs) {
    dem::prepare_parallel_runs(a.cal.workers);
  }
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // progress reaches a log file as it happens
  dem::stop_children_with_the_program();     // SIGTERM says what it stopped, and stops the children too
  std::optional<Kokkos::ScopeGuard> kokkos;
  if (cmd.kokkos) {
    kokkos.emplace(argc, argv);
    // Steps run here, on this process's threads (a calibration's runs are children of one thread each); on a GPU
    // one host thread drives them, and the device's concurrency (270,336 on an H200) shares no host core.
    const int threads = cmd.parallel_runs || dem::kOnDevice ? 1 : Kokkos::DefaultExecutionSpace().concurrency();
    if (const std::string note = dem::busy_machine_note(threads); !note.empty())
      std::fprintf(stderr, "triaxdem: %s\n", note.c_str());
  }
  try {
    return cmd.run(a);
  } catch (const dem::DataError& e) {
    return fail(std::string("triaxdem: data error: ") + e.what());
  } catch (const dem::ConfigError& e) {
    return fail(std::string("triaxdem: config error: ") + e.what());
  } catch (const std::exception& e) {
    return fail(std::string("triaxdem: error: ") + e.what());
  }
}
