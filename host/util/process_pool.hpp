#pragma once
/// The one process pool: pieces of work in child processes, up to `workers` at once, the next starting as soon as any
/// ends. Serves the calibration's parallel runs (forked_runs.hpp: results back through a pipe) and the study's
/// cases (the program itself, exec'd, with its log in the case's folder). Each child holds the write end of a pipe
/// until it ends (exec keeps it open), so the parent learns that a piece has ended, or has begun to send its
/// result, from that pipe alone.
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

namespace dem {

struct PoolWork {
  std::size_t pieces = 0;
  int workers = 1;
  /// Piece j's work relative to the others' (unset: all alike): the pool starts the longest first, so that the last
  /// to end is not a long one started late. Results do not depend on the order.
  std::function<double(std::size_t)> cost;
  /// In the parent, before piece j starts: false leaves it out (finished before, or the pool is stopping).
  std::function<bool(std::size_t)> before;
  /// In the child: the piece, with `fd` the write end of its pipe. The child ends with exit status 0 when this
  /// returns (no atexit handlers, no Kokkos finalize: the parent owns those), or exec's another program.
  std::function<void(std::size_t, int)> child;
  /// In the parent as piece j's pipe turns readable: reads its result (none: return true); false where it is cut
  /// short. Results come in the order the children end: put result j in its place.
  std::function<bool(std::size_t, int)> collect;
  /// Spread over ranks (ranks.hpp), before piece j runs again on another rank after a signal killed its process part
  /// way: readies it to start over from what that process left (unset: it starts as the first time).
  std::function<void(std::size_t)> again;
  /// In the parent once piece j has ended: its exit status as a shell gives it (128 + the signal that ended it),
  /// or -1 where collect found its result cut short.
  std::function<void(std::size_t, int)> after;
  /// In the parent, for each running piece, every `waiting_seconds` in which none ends (unset: nothing): a piece
  /// that takes minutes says how it goes.
  std::function<void(std::size_t)> waiting;
  int waiting_seconds = 30;
};

/// Runs the pieces; `what` names them in the error when a pipe or a process cannot be made. In a job spread over
/// MPI ranks (ranks.hpp) the ranks run them, one piece each at a time; else this process's children.
void run_pool(const PoolWork& w, const char* what);
/// The pieces in this process's children, whatever the ranks.
void run_pool_here(const PoolWork& w, const char* what);
/// A child process with a pipe back to this one. In the child: body(the pipe's write end), then exit status 0 with
/// no atexit handlers (the parent owns those). In the parent: the child's pid, with `read_fd` the pipe's read end.
/// Buffered output is flushed first, so that a child does not write it again; `what` names the work in the error
/// when the pipe or the process cannot be made.
int start_child(const char* what, int& read_fd, const std::function<void(int)>& body);
/// Waits for a child started so; its exit status as a shell gives it (128 + the signal that ended it).
int wait_child(int pid);

/// SIGINT and SIGTERM from here on: the program says what stopped it and the job's note (set_stop_note), stops the
/// child processes it is running, and ends as the signal ends it (exit status 128 + the signal). A stage that keeps
/// checkpoints catches them for its time (StopSignals) and ends its own way. Children start with the default again.
void stop_children_with_the_program();
/// What a stop leaves and how to go on ("its runs so far are kept: --resume FOLDER continues"); "" for none.
void set_stop_note(const std::string& note);
/// The order the pieces start in: by cost, longest first, ties (and all, without a cost) in index order.
std::vector<std::size_t> start_order(const PoolWork& w);

/// How this process's pools have been used so far, for a job's account of its workers: a pool of W workers that
/// runs for T seconds offers W T worker-seconds; what its pieces did not use, its workers sat idle (the last pieces
/// of a batch, while the longest runs).
struct PoolUse {
  long pieces = 0;
  double busy = 0;      ///< seconds the pieces ran, summed
  double offered = 0;   ///< seconds each pool ran times its workers
  double wall = 0;      ///< seconds the pools ran
  double idle() const { return offered - busy; }
};
PoolUse pool_use();
/// One pool as it ran: its name, its workers, its wall time and each piece's run time (s), in the order they ended.
struct PoolRecord {
  std::string what;
  int workers = 1;
  double wall = 0;
  std::vector<double> piece_seconds;
};
/// Adds a pool to pool_use() and to pools_csv() (run_pool does; so does the pool spread over ranks).
void record_pool(PoolRecord r);
/// This process's pools so far as CSV (pools.csv in a job's folder), with the job's wall time in its first line:
/// what tools/schedule_projection.py needs to project the job's wall time on more ranks.
std::string pools_csv(double job_wall);

}  // namespace dem
