#pragma once
/// The program's commands (host/cli/commands.cpp): what the command line sets, and the table of commands. A command is
/// one entry of command_table(): its name, help, options and the function it runs (host/cli/job.hpp). Only the
/// program's own files (this one's, main.cpp) parse options with CLI11.
#include <string>
#include <vector>

#include "host/study/calibration_jobs.hpp"
#include "host/study/study.hpp"

namespace CLI {
class App;
}

namespace dem::cli {

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
  std::string compression_path = "oedometer";
  std::vector<double> compression_kpa;
};


/// A command: its name and help, its options, the function it runs, and how it runs.
struct Command {
  const char* name;
  const char* help;
  void (*options)(CLI::App*, Args&);
  int (*run)(Args&);
  bool over_ranks = false;     ///< may be spread over MPI ranks (its runs are independent of each other)
  bool parallel_runs = false;  ///< its simulator runs are child processes of one thread each (-j)
  bool kokkos = true;          ///< false: it only starts programs of its own (no Kokkos here)
};

/// Every command, in the order --help lists them.
const std::vector<Command>& command_table();

/// "study, calibrate and diagnose": the commands that spread over MPI ranks.
std::string over_ranks_names();

/// OMP_NUM_THREADS as the OpenMP runtime would take it, checked before the runtime starts. Empty: fine.
std::string omp_threads_problem();

}  // namespace dem::cli
