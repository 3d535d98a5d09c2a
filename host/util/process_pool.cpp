#include "host/util/process_pool.hpp"

#include "host/util/progress.hpp"
#include "host/util/ranks.hpp"

#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <numeric>
#include <stdexcept>
#include <string>
#include <vector>

namespace dem {

namespace {

PoolUse use_so_far;
std::vector<PoolRecord> records;

// The children running now, for a stop signal's handler: lock-free atomics, which a handler may read.
constexpr int kMaxChildren = 1024;
std::atomic<int> child_pids[kMaxChildren];
char stop_note[1024];

void remember_child(int pid) {
  for (std::atomic<int>& p : child_pids) {
    int free = 0;
    if (p.compare_exchange_strong(free, pid)) return;
  }
}

void forget_child(int pid) {
  for (std::atomic<int>& p : child_pids) {
    int was = pid;
    if (p.compare_exchange_strong(was, 0)) return;
  }
}

/// Async-signal-safe: write(2), kill(2), signal and raise only.
void say(const char* text) {
  std::size_t n = 0;
  while (text[n]) ++n;
  if (::write(2, text, n) < 0) return;
}

void on_stop_signal(int sig) {
  say(sig == SIGINT ? "triaxdem: stopped by SIGINT" : "triaxdem: stopped by SIGTERM");
  bool children = false;
  for (std::atomic<int>& p : child_pids)
    if (const int pid = p.load(); pid > 0) children = ::kill(pid, SIGTERM) == 0 || children;
  say(children ? "; its child processes stopped with it" : "");
  if (stop_note[0]) {
    say("; ");
    say(stop_note);
  }
  say("\n");
  ::signal(sig, SIG_DFL);
  ::raise(sig);
}

using Clock = std::chrono::steady_clock;

}  // namespace

PoolUse pool_use() { return use_so_far; }

void record_pool(PoolRecord r) {
  for (double s : r.piece_seconds) use_so_far.busy += s;
  use_so_far.pieces += static_cast<long>(r.piece_seconds.size());
  use_so_far.wall += r.wall;
  use_so_far.offered += r.wall * r.workers;
  records.push_back(std::move(r));
}

std::string pools_csv(double job_wall) {
  std::string out = "# the process pools of a job: each piece's run time (s); job_wall_s " +
                    std::to_string(job_wall) + "\npool,what,workers,pool_wall_s,piece,seconds\n";
  char line[256];
  for (std::size_t p = 0; p < records.size(); ++p)
    for (std::size_t k = 0; k < records[p].piece_seconds.size(); ++k) {
      std::snprintf(line, sizeof line, "%zu,%s,%d,%.3f,%zu,%.3f\n", p + 1, records[p].what.c_str(), records[p].workers,
                    records[p].wall, k + 1, records[p].piece_seconds[k]);
      out += line;
    }
  return out;
}

std::vector<std::size_t> start_order(const PoolWork& w) {
  std::vector<std::size_t> order(w.pieces);
  std::iota(order.begin(), order.end(), std::size_t{0});
  if (w.cost)
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return w.cost(a) > w.cost(b); });
  return order;
}

int start_child(const char* what, int& read_fd, const std::function<void(int)>& body) {
  std::cout.flush();
  std::fflush(nullptr);
  int fd[2];
  if (::pipe(fd) != 0) throw std::runtime_error(std::string(what) + ": cannot create a pipe for a child process");
  const pid_t pid = ::fork();
  if (pid < 0) throw std::runtime_error(std::string(what) + ": cannot start a child process (fork failed)");
  if (pid == 0) {
    ::signal(SIGINT, SIG_DFL);  // a child ends at the parent's word, saying nothing of its own
    ::signal(SIGTERM, SIG_DFL);
    for (std::atomic<int>& p : child_pids) p.store(0);  // the parent's children are not this one's
    ::close(fd[0]);
    body(fd[1]);
    std::fflush(nullptr);
    ::_exit(0);
  }
  ::close(fd[1]);
  read_fd = fd[0];
  remember_child(pid);
  return pid;
}

int wait_child(int pid) {
  int ws = 0;
  while (::waitpid(pid, &ws, 0) < 0 && errno == EINTR) {
  }
  forget_child(pid);
  return WIFEXITED(ws) ? WEXITSTATUS(ws) : 128 + WTERMSIG(ws);
}

void stop_children_with_the_program() {
  ::signal(SIGINT, on_stop_signal);
  ::signal(SIGTERM, on_stop_signal);
}

void set_stop_note(const std::string& note) {
  const std::size_t n = std::min(note.size(), sizeof stop_note - 1);
  std::copy(note.begin(), note.begin() + static_cast<std::ptrdiff_t>(n), stop_note);
  stop_note[n] = '\0';
}

void run_pool(const PoolWork& w, const char* what) {
  // A piece whose process a signal ended (the machine's out-of-memory killer, a node's fault) gets a second rank.
  constexpr int kTries = 2;
  if (ranks::spread()) ranks::run_pool_on_ranks(w, what, kTries);
  else run_pool_here(w, what);
}

void run_pool_here(const PoolWork& w, const char* what) {
  struct Child {
    std::size_t j;
    pid_t pid;
    int fd;
    Clock::time_point start;
  };
  const std::size_t workers = static_cast<std::size_t>(w.workers > 1 ? w.workers : 1);
  // Recorded as the pool ends, whichever way: by then every child it started has ended.
  struct Account {
    PoolRecord r;
    Clock::time_point t0 = Clock::now();
    ~Account() {
      r.wall = seconds_since(t0);
      record_pool(std::move(r));
    }
  } account{{what, static_cast<int>(std::min(workers, std::max<std::size_t>(w.pieces, 1))), 0, {}}};
  std::vector<Child> running;
  const std::vector<std::size_t> order = start_order(w);
  std::size_t next = 0;
  for (;;) {
    while (next < w.pieces && running.size() < workers) {
      const std::size_t j = order[next++];
      if (w.before && !w.before(j)) continue;
      int fd = -1;
      const pid_t pid = start_child(what, fd, [&](int out) {
        for (const Child& c : running) ::close(c.fd);  // the siblings' pipes are the parent's to read
        w.child(j, out);
      });
      running.push_back({j, pid, fd, Clock::now()});
    }
    if (running.empty()) return;
    std::vector<pollfd> polled;
    for (const Child& c : running) polled.push_back({c.fd, POLLIN, 0});
    const int ready = ::poll(polled.data(), polled.size(), w.waiting ? 1000 * w.waiting_seconds : -1);
    if (ready < 0) {
      if (errno == EINTR) continue;
      throw std::runtime_error(std::string(what) + ": cannot wait for the child processes (poll failed)");
    }
    if (ready == 0) {
      for (const Child& c : running) w.waiting(c.j);
      continue;
    }
    std::size_t k = 0;
    while (polled[k].revents == 0) ++k;
    const Child c = running[k];
    running.erase(running.begin() + static_cast<std::ptrdiff_t>(k));
    const bool whole = !w.collect || w.collect(c.j, c.fd);
    ::close(c.fd);
    const int status = wait_child(c.pid);
    account.r.piece_seconds.push_back(seconds_since(c.start));
    if (w.after) w.after(c.j, whole ? status : -1);
  }
}

}  // namespace dem
