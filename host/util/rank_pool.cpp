#include "host/util/ranks.hpp"

#include "host/util/process_pool.hpp"

#ifdef TRIAXDEM_HAVE_MPI
#include <poll.h>
#include <sys/prctl.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <functional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "host/util/ranks_mpi.hpp"
#endif

namespace dem::ranks {

#ifdef TRIAXDEM_HAVE_MPI

namespace {

using detail::idle_recv;

enum Tag : int { kPiece = 1, kHeader = 2, kBytes = 3, kAlive = 4 };

/// collect(j, fd) on bytes that came from another rank, through an unnamed temporary file (a pipe could not hold
/// a large result before it is read).
bool collect_bytes(const PoolWork& w, std::size_t j, const std::vector<char>& bytes) {
  if (!w.collect) return true;
  std::FILE* f = std::tmpfile();
  if (!f) throw std::runtime_error("cannot make a temporary file for a rank's result");
  const bool written = bytes.empty() || std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size();
  std::fflush(f);
  std::rewind(f);
  const bool whole = written && w.collect(j, ::fileno(f));
  std::fclose(f);
  return whole;
}

/// What the leader saw, in order, for the shadows to go through the same callbacks once the pool ends.
struct Event {
  long j = 0;
  int ran = 0;     // 0: before(j) said `status` (1 run, 0 leave out); 1: the piece ended with `status`; 2: again(j)
  int status = 0;
  std::vector<char> bytes;
};

std::vector<char> pack_events(const std::vector<Event>& ev) {
  std::vector<char> out;
  auto put = [&](const void* p, std::size_t n) {
    out.insert(out.end(), static_cast<const char*>(p), static_cast<const char*>(p) + n);
  };
  for (const Event& e : ev) {
    const long head[4] = {e.j, e.ran, e.status, static_cast<long>(e.bytes.size())};
    put(head, sizeof head);
    put(e.bytes.data(), e.bytes.size());
  }
  return out;
}

std::vector<Event> unpack_events(const std::vector<char>& in) {
  std::vector<Event> ev;
  for (std::size_t at = 0; at < in.size();) {
    long head[4];
    std::memcpy(head, in.data() + at, sizeof head);
    at += sizeof head;
    Event e{head[0], static_cast<int>(head[1]), static_cast<int>(head[2]), {}};
    e.bytes.assign(in.begin() + static_cast<std::ptrdiff_t>(at),
                   in.begin() + static_cast<std::ptrdiff_t>(at + static_cast<std::size_t>(head[3])));
    at += static_cast<std::size_t>(head[3]);
    ev.push_back(std::move(e));
  }
  return ev;
}

/// Seconds without word from a rank that holds a piece before the leader takes it for dead and gives the piece to
/// another (TRIAXDEM_RANK_TIMEOUT_S, default 60); a rank running a piece says it lives ten times as often.
double rank_timeout() {
  const char* s = std::getenv("TRIAXDEM_RANK_TIMEOUT_S");
  const double t = s ? std::atof(s) : 0;
  return t > 0 ? t : 60;
}

/// On a shadow: piece j in a child process, as the local pool runs one, with word to the leader that this rank lives
/// while it runs; its bytes and exit status then go to the leader.
void serve_piece(const PoolWork& w, std::size_t j, const char* what) {
  int fd = -1;
  const int pid = start_child(what, fd, [&](int out) {
    // The piece ends with its rank: a piece given to another rank must not race an orphan in the same folder.
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    // The child is a process of its own, as the local pool's are: it writes what they write, and a program it
    // starts does not take itself for a rank.
    detail::become_single_process();
    w.child(j, out);
  });
  std::vector<char> bytes;
  bool whole = true;
  const int beat_ms = static_cast<int>(100 * rank_timeout());
  for (char buf[1 << 16];;) {
    pollfd p{fd, POLLIN, 0};
    const int ready = ::poll(&p, 1, beat_ms);
    if (ready == 0 || (ready < 0 && errno == EINTR)) {
      const long beat = static_cast<long>(j);
      MPI_Send(&beat, 1, MPI_LONG, 0, kAlive, MPI_COMM_WORLD);
      continue;
    }
    const ssize_t r = ready < 0 ? -1 : ::read(fd, buf, sizeof buf);
    if (r == 0) break;
    if (r < 0 && errno == EINTR) continue;
    if (r < 0) {
      whole = false;
      break;
    }
    bytes.insert(bytes.end(), buf, buf + r);
  }
  ::close(fd);
  const int exit_status = wait_child(pid);
  const int status = whole ? exit_status : -1;
  const long head[3] = {static_cast<long>(j), status, static_cast<long>(bytes.size())};
  MPI_Send(head, 3, MPI_LONG, 0, kHeader, MPI_COMM_WORLD);
  MPI_Send(bytes.data(), static_cast<int>(bytes.size()), MPI_CHAR, 0, kBytes, MPI_COMM_WORLD);
}

/// The ranks the leader still counts on: a rank taken for dead gets no piece again in this job.
std::vector<char>& alive() {
  static std::vector<char> a(static_cast<std::size_t>(size()), 1);
  return a;
}

/// The leader's side of a pool: the queue, the ranks' pieces, their results and the record for the shadows.
class Leader {
 public:
  Leader(const PoolWork& w, const char* what, int tries, std::function<bool(std::size_t)> before)
      : w_(w), what_(what), tries_(tries), before_(std::move(before)), tried_(w.pieces, 0), last_rank_(w.pieces, -1),
        started_(w.pieces), holds_(static_cast<std::size_t>(size()), -1), heard_(static_cast<std::size_t>(size())),
        order_(start_order(w)) {
    for (int r = size() - 1; r >= 1; --r)
      if (alive()[static_cast<std::size_t>(r)]) idle_.push_back(r);
  }

  std::vector<Event> run() {
    const Clock::time_point t0 = Clock::now();
    if (idle_.empty()) throw std::runtime_error(std::string(what_) + ": no rank is left to run the pieces");
    for (;;) {
      hand_out();
      if (busy_ == 0) break;
      wait_for_word();
    }
    record_pool({what_, size() - 1, seconds(t0), std::move(piece_seconds_)});
    return std::move(events_);
  }

 private:
  using Clock = std::chrono::steady_clock;
  static double seconds(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

  /// The next piece for an idle rank: one to run again first, else the next that before() lets start.
  std::size_t next_piece() {
    if (!again_.empty()) {
      const std::size_t j = again_.front();
      again_.pop_front();
      if (w_.again) w_.again(j);
      events_.push_back({static_cast<long>(j), 2, 0, {}});
      return j;
    }
    while (next_ < w_.pieces) {
      const std::size_t k = order_[next_++];
      const bool go = before_(k);
      events_.push_back({static_cast<long>(k), 0, go ? 1 : 0, {}});
      if (go) return k;
    }
    return w_.pieces;
  }

  void hand_out() {
    while (!idle_.empty()) {
      const std::size_t j = next_piece();
      if (j == w_.pieces) return;
      // Another rank than the one where the piece failed, where one is idle.
      std::size_t pick = idle_.size() - 1;
      for (std::size_t i = 0; i < idle_.size(); ++i)
        if (idle_[i] != last_rank_[j]) pick = i;
      const int r = idle_[pick];
      idle_.erase(idle_.begin() + static_cast<std::ptrdiff_t>(pick));
      const long piece[3] = {static_cast<long>(j), tried_[j], 0};
      MPI_Send(piece, 3, MPI_LONG, r, kPiece, MPI_COMM_WORLD);
      started_[j] = heard_[static_cast<std::size_t>(r)] = Clock::now();
      last_rank_[j] = r;
      holds_[static_cast<std::size_t>(r)] = static_cast<long>(j);
      ++busy_;
    }
  }

  /// Until a rank's piece ends, or a rank that holds one is taken for dead.
  void wait_for_word() {
    const double timeout = rank_timeout();
    for (;;) {
      int flag = 0;
      MPI_Status st;
      MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &st);
      if (flag) {
        const std::size_t r = static_cast<std::size_t>(st.MPI_SOURCE);
        if (st.MPI_TAG == kAlive) {
          long j;
          MPI_Recv(&j, 1, MPI_LONG, st.MPI_SOURCE, kAlive, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
          heard_[r] = Clock::now();
          continue;
        }
        long head[3];
        MPI_Recv(head, 3, MPI_LONG, st.MPI_SOURCE, kHeader, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        std::vector<char> bytes(static_cast<std::size_t>(head[2]));
        MPI_Recv(bytes.data(), static_cast<int>(bytes.size()), MPI_CHAR, st.MPI_SOURCE, kBytes, MPI_COMM_WORLD,
                 MPI_STATUS_IGNORE);
        if (!alive()[r]) continue;  // taken for dead before it answered: its piece went elsewhere
        ended(st.MPI_SOURCE, static_cast<std::size_t>(head[0]), static_cast<int>(head[1]), std::move(bytes));
        return;
      }
      for (int q = 1; q < size(); ++q) {
        const std::size_t r = static_cast<std::size_t>(q);
        if (holds_[r] < 0 || seconds(heard_[r]) < timeout) continue;
        const std::size_t j = static_cast<std::size_t>(holds_[r]);
        alive()[r] = 0;
        holds_[r] = -1;
        --busy_;
        char why[160];
        std::snprintf(why, sizeof why, "rank %d has not answered for %.0f s (it died, or its node did)", q, timeout);
        run_again_or_fail(j, why, -1);
        if (busy_ == 0 && idle_.empty()) throw std::runtime_error(std::string(what_) + ": no rank is left");
        return;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
  }

  void ended(int r, std::size_t j, int status, std::vector<char> bytes) {
    --busy_;
    holds_[static_cast<std::size_t>(r)] = -1;
    idle_.push_back(r);
    piece_seconds_.push_back(seconds(started_[j]));
    if (status > 128) {
      char why[96];
      std::snprintf(why, sizeof why, "its process was killed on rank %d (signal %d)", r, status - 128);
      run_again_or_fail(j, why, status);
      return;
    }
    const bool whole = status >= 0 && collect_bytes(w_, j, bytes);
    finish(j, whole ? status : -1, std::move(bytes));
  }

  void finish(std::size_t j, int status, std::vector<char> bytes) {
    if (w_.after) w_.after(j, status);
    events_.push_back({static_cast<long>(j), 1, status, std::move(bytes)});
  }

  /// A piece cut short by a signal or by its rank's death runs again, `tries_` times in all; then it has failed with
  /// `status`.
  void run_again_or_fail(std::size_t j, const char* why, int status) {
    if (++tried_[j] < tries_) {
      std::printf("%s: piece %zu of %zu: %s; it runs again, on another rank where one is idle (try %d of %d)\n",
                  what_, j + 1, w_.pieces, why, tried_[j] + 1, tries_);
      again_.push_back(j);
      return;
    }
    std::printf("%s: piece %zu of %zu: %s; it has failed after %d tries\n", what_, j + 1, w_.pieces, why, tries_);
    finish(j, status, {});
  }

  const PoolWork& w_;
  const char* what_;
  int tries_;
  std::function<bool(std::size_t)> before_;
  std::vector<int> tried_, last_rank_;
  std::vector<Clock::time_point> started_;
  std::vector<long> holds_;                 // per rank: the piece it runs, or -1
  std::vector<Clock::time_point> heard_;    // per rank: when it last said it lives
  std::vector<int> idle_;
  std::deque<std::size_t> again_;
  std::vector<Event> events_;
  std::vector<std::size_t> order_;
  std::size_t next_ = 0;
  int busy_ = 0;
  std::vector<double> piece_seconds_;  // each run's time, killed ones included (their rank's time was spent)
};

}  // namespace

void run_pool_on_ranks(const PoolWork& w, const char* what, int tries) {
  std::vector<char> before_called(w.pieces, 0);
  std::vector<int> again_called(w.pieces, 0);  // the times again(j) was called on this rank
  auto call_before = [&](std::size_t j) {
    before_called[j] = 1;
    return !w.before || w.before(j);
  };
  if (leader()) {
    const std::vector<char> record = pack_events(Leader(w, what, tries, call_before).run());
    // Every live rank goes through the leader's callbacks, so that all hold the same results and go on alike.
    bool lost = false;
    for (int r = 1; r < size(); ++r) lost = lost || !alive()[static_cast<std::size_t>(r)];
    if (lost) detail::note_lost_rank();
    const long stop[3] = {-1, static_cast<long>(record.size()), lost};
    for (int r = 1; r < size(); ++r) {
      if (!alive()[static_cast<std::size_t>(r)]) continue;
      MPI_Send(stop, 3, MPI_LONG, r, kPiece, MPI_COMM_WORLD);
      MPI_Send(record.data(), static_cast<int>(record.size()), MPI_CHAR, r, kBytes, MPI_COMM_WORLD);
    }
    return;
  }
  std::vector<char> record;
  for (;;) {
    long piece[3];
    idle_recv(piece, 3, MPI_LONG, 0, kPiece);
    if (piece[0] < 0) {
      if (piece[2] != 0) detail::note_lost_rank();
      record.resize(static_cast<std::size_t>(piece[1]));
      MPI_Recv(record.data(), static_cast<int>(record.size()), MPI_CHAR, 0, kBytes, MPI_COMM_WORLD,
               MPI_STATUS_IGNORE);
      break;
    }
    const std::size_t j = static_cast<std::size_t>(piece[0]);
    if (!before_called[j]) call_before(j);
    for (; again_called[j] < piece[1]; ++again_called[j])
      if (w.again) w.again(j);
    serve_piece(w, j, what);
  }
  std::vector<int> agains(w.pieces, 0);
  for (const Event& e : unpack_events(record)) {
    const std::size_t j = static_cast<std::size_t>(e.j);
    if (e.ran == 2) {
      if (++agains[j] > again_called[j] && w.again) w.again(j);
      continue;
    }
    if (!e.ran) {
      if (!before_called[j]) call_before(j);
      continue;
    }
    if (e.status >= 0) collect_bytes(w, j, e.bytes);
    if (w.after) w.after(j, e.status);
  }
}

#else

void run_pool_on_ranks(const PoolWork& w, const char* what, int) { run_pool_here(w, what); }

#endif

}  // namespace dem::ranks
