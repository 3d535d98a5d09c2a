/// The `study` command: each case a child process of this program (the process pool, host/util/process_pool.hpp),
/// as many at once as the machine has cores to spare, and the table rewritten as each one ends.
#include <fcntl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>

#include "host/cli/job.hpp"
#include "host/engine/checkpoint.hpp"
#include "host/io/io_hdf5.hpp"
#include "host/study/study.hpp"
#include "host/util/busy_machine.hpp"
#include "host/util/process_pool.hpp"
#include "host/util/progress.hpp"
#include "host/util/ranks.hpp"
#include "kernels/core/types.hpp"

namespace dem {

namespace fs = std::filesystem;

namespace {

/// A case's own last progress line (its log holds \r-separated updates), so that a long case is not a silent one.
std::string last_log_line(const std::string& path) {
  std::ifstream in(path);
  std::string log((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  while (!log.empty() && (log.back() == '\n' || log.back() == '\r' || log.back() == ' ')) log.pop_back();
  const std::size_t cut = log.find_last_of("\r\n");
  const std::string last = cut == std::string::npos ? log : log.substr(cut + 1);
  return last.empty() ? "(nothing in its log yet)" : last;
}

/// How a case starts: afresh, from its checkpoint (study --resume, or a rerun after its process was killed), or over
/// the outputs a killed process left without a checkpoint.
enum class Start : char { fresh, resume, overwrite };

/// In the child of piece `c`: `self job config -o folder` with its output in folder/log.txt and `threads` OpenMP
/// threads. Resumed, the case continues from its checkpoint, and its log goes on.
[[noreturn]] void exec_case(const char* self, const StudyCase& c, const std::string& folder, int threads, Start start) {
  const bool resume = start == Start::resume;
  const std::string log = folder + "/log.txt";
  const int fd = open(log.c_str(), O_WRONLY | O_CREAT | (resume ? O_APPEND : O_TRUNC), 0644);
  if (fd >= 0) {
    dup2(fd, 1);
    dup2(fd, 2);
    close(fd);
  }
  setenv("OMP_NUM_THREADS", std::to_string(threads).c_str(), 1);
  setenv("OMP_PROC_BIND", "false", 0);
  const char* flag = resume ? "--resume" : start == Start::overwrite ? "--overwrite" : nullptr;
  execl(self, self, c.job.c_str(), c.config.c_str(), "-o", folder.c_str(), flag, static_cast<char*>(nullptr));
  std::perror("study: exec");
  _exit(127);
}

/// The study's table on the terminal: each case's headline numbers and its errors against each compared file, then
/// each file's mean and largest error. Returns the number of failed cases.
int print_study_table(const std::vector<StudyCase>& cases, const StudyTable& table, const StudyOptions& opt) {
  const std::vector<PeakComparison>& cmp = table.cmp;
  int failed = 0;
  std::printf("\n%-14s %8s %6s %6s %10s %9s %10s %10s %8s", "case", "s3 kPa", "mu_s", "mu_r", "q_peak kPa",
              "phi deg", "eps_pk %", "q_end kPa", "max dil");
  for (std::size_t j = 0; j < cmp.size(); ++j) std::printf(" %7s%zu %6s%zu", "ref kPa ", j + 1, "err % ", j + 1);
  std::printf("\n");
  for (std::size_t k = 0; k < cases.size(); ++k) {
    const StudyCase& c = cases[k];
    if (!table.ok[k]) {
      ++failed;
      std::printf("%-14s FAILED: see %s/%s/log.txt\n", c.name.c_str(), opt.output.c_str(), c.name.c_str());
      continue;
    }
    const TestSummary& s = table.summaries[k];
    std::printf("%-14s %8.0f %6.3f %6.3f %10.1f %9.2f %10.2f %10.1f %8.3f", c.name.c_str(), s.sigma3 / 1e3, s.mu_s,
                s.mu_r, s.q_peak / 1e3, s.phi_peak_deg, 100 * s.eps_a_peak, s.q_end / 1e3, s.max_dilatancy);
    for (const PeakComparison& p : cmp) {
      if (std::isfinite(p.error[k])) std::printf(" %9.1f %8.1f", p.measured[k] / 1e3, 100 * p.error[k]);
      else std::printf(" %9s %8s", "-", "-");
    }
    std::printf("\n");
  }
  for (std::size_t j = 0; j < cmp.size(); ++j) {
    const PeakComparison& p = cmp[j];
    if (p.matched == 0) {
      std::printf("ref %zu, %s: no case matched (a case needs [run] material and its sigma3 in the file)\n", j + 1,
                  p.source.c_str());
      continue;
    }
    std::printf("ref %zu, %s (q %s): %d of %zu cases matched; q_peak off by %.1f%% on average (|error|), %.1f%% "
                "at most (%s)\n", j + 1, p.source.c_str(), name_of(p.measure), p.matched, cases.size(),
                100 * p.mean_abs_error, 100 * p.max_abs_error, cases[p.worst].name.c_str());
  }
  return failed;
}

/// The schedule's efficiency: the cases' run times summed, against the wall time times the workers (ranks).
void print_efficiency(int workers) {
  const PoolUse use = pool_use();
  if (use.pieces == 0) return;
  std::printf("study: %ld cases ran for %s in all, in %s on %d %s: %.0f%% efficiency (the rest idle, waiting for the "
              "last case)\n", use.pieces, format_duration(use.busy).c_str(), format_duration(use.wall).c_str(),
              workers, ranks::spread() ? "ranks" : "workers", 100 * use.busy / std::max(use.offered, 1e-9));
}

/// Cases at once and OpenMP threads each: the options', else the cores shared out (one case at a time on a GPU,
/// one a rank where spread over MPI ranks, the leader handing them out).
std::pair<int, int> share_cores(const StudyOptions& opt, std::size_t cases) {
  const int cores = machine_cores();
  int workers = std::clamp(opt.workers > 0 ? opt.workers : cores / 2, 1, static_cast<int>(cases));
  if (kOnDevice && workers > 1) {
    if (opt.workers > 1)
      std::printf("study: one case at a time on the GPU, not %d: processes that share a GPU time-slice it and run "
                  "slower together than one after another\n", opt.workers);
    workers = 1;
  }
  if (ranks::spread()) workers = ranks::size() - 1;
  const int threads =
      opt.threads > 0 ? opt.threads : std::max(1, cores / (ranks::spread() ? ranks::per_node() : workers));
  return {workers, threads};
}

/// A run's own folder (its series and checkpoint at the top) is no study's: their files would mix.
void refuse_run_folder(const std::string& output) {
  for (const char* own : {"series.csv", "summary.csv", "checkpoint.h5"})
    if (fs::exists(fs::path(output) / own))
      throw std::runtime_error("study -o " + output + ": a run's folder (" + own + " in it): a study writes a "
                               "folder per case and its table there; name another folder");
}

}  // namespace

int study_job(const std::vector<std::string>& inputs, const StudyOptions& opt, const char* self_exe) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::vector<StudyCase> cases = study_cases(inputs);
  std::vector<MeasuredData> compare;  // read before anything runs: a bad file stops the study at once
  for (const std::string& f : opt.compare) compare.push_back(load_measured(f));
  set_stop_note("the finished cases are kept in " + opt.output + ": the same command with --resume runs the rest, "
                "the triaxial cases from their checkpoints");
  const std::pair<int, int> share = share_cores(opt, cases.size());
  const int workers = share.first, threads = share.second;
  refuse_run_folder(opt.output);
  fs::create_directories(opt.output);
  if (ranks::spread()) std::printf("study: spread over %d MPI ranks\n", ranks::size());
  std::printf("study: %zu cases, %d at a time with %d OpenMP threads each; logs in %s/<case>/log.txt\n",
              cases.size(), workers, threads, opt.output.c_str());
  std::vector<int> status(cases.size(), -1);
  std::size_t done = 0;
  auto finished_before = [&](std::size_t k) {
    return opt.resume && fs::exists(opt.output + "/" + cases[k].name + "/summary.csv");
  };
  long kept = 0;
  for (std::size_t k = 0; k < cases.size(); ++k) kept += finished_before(k);
  // Kept cases took no time in this run: left out of the rate behind the ETA.
  Progress progress("study", static_cast<long>(cases.size()), kept);
  std::vector<std::chrono::steady_clock::time_point> started(cases.size());
  std::vector<Start> start(cases.size(), Start::fresh);
  auto folder = [&](std::size_t k) { return opt.output + "/" + cases[k].name; };
  // Only the triaxial job checkpoints; a periodic case (minutes) starts again.
  auto has_checkpoint = [&](std::size_t k) {
    return cases[k].job == "triaxial" && fs::exists(checkpoint_path(folder(k)));
  };
  PoolWork w;
  w.pieces = cases.size();
  w.workers = workers;
  w.cost = [&](std::size_t k) { return cases[k].cost; };
  w.before = [&](std::size_t k) {
    if (finished_before(k)) {
      std::printf("study: %s finished before (summary.csv): kept\n", cases[k].name.c_str());
      status[k] = 0;
      ++done;
      return false;
    }
    start[k] = opt.resume && has_checkpoint(k) ? Start::resume : Start::fresh;
    fs::create_directories(folder(k));
    started[k] = std::chrono::steady_clock::now();
    std::printf("study: %s %s (%s)\n", start[k] == Start::resume ? "resumed" : "started", cases[k].name.c_str(),
                cases[k].config.c_str());
    return true;
  };
  w.again = [&](std::size_t k) { start[k] = has_checkpoint(k) ? Start::resume : Start::overwrite; };
  w.child = [&](std::size_t k, int) { exec_case(self_exe, cases[k], folder(k), threads, start[k]); };
  w.after = [&](std::size_t k, int st) {
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - started[k]).count();
    status[k] = st;
    ++done;
    std::printf("study: %s %s after %s\n", cases[k].name.c_str(),
                st == 0 ? "finished" : ("FAILED (exit " + std::to_string(st) + ", see its log.txt)").c_str(),
                format_duration(secs).c_str());
    io::write_text_atomic(opt.output + "/study_summary.csv", study_table(cases, status, opt.output, compare).csv);
    progress.update(static_cast<long>(done));
  };
  w.waiting = [&](std::size_t k) {
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - started[k]).count();
    std::printf("study: %s running for %s: %s\n", cases[k].name.c_str(), format_duration(secs).c_str(),
                last_log_line(folder(k) + "/log.txt").c_str());
    std::fflush(stdout);
  };
  run_pool(w, "study");
  progress.finish("");
  print_efficiency(workers);

  const StudyTable table = study_table(cases, status, opt.output, compare);
  const int failed = print_study_table(cases, table, opt);
  io::write_text_atomic(opt.output + "/study_summary.csv", table.csv);
  io::write_text_atomic(opt.output + "/pools.csv",
                        pools_csv(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()));
  std::printf("\nstudy: summary in %s/study_summary.csv; the cases' run times in pools.csv\n", opt.output.c_str());
  if (run_plot_script("plot_study.py", {opt.output}))
    std::printf("study: figure in %s/study.png\n", opt.output.c_str());
  return failed == 0 ? 0 : 1;
}

}  // namespace dem
