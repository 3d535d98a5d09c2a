#include "host/util/forked_runs.hpp"

#include "host/util/process_pool.hpp"

#include <unistd.h>

#include <cstdio>
#include <stdexcept>
#include <string>

namespace dem {

void put_bytes(int fd, const void* p, std::size_t n) {
  for (const char* c = static_cast<const char*>(p); n > 0;) {
    const ssize_t w = ::write(fd, c, n);
    if (w <= 0) ::_exit(3);
    c += w, n -= static_cast<std::size_t>(w);
  }
}

bool get_bytes(int fd, void* p, std::size_t n) {
  for (char* c = static_cast<char*>(p); n > 0;) {
    const ssize_t r = ::read(fd, c, n);
    if (r <= 0) return false;
    c += r, n -= static_cast<std::size_t>(r);
  }
  return true;
}

void forked_runs(std::size_t n, int workers, const std::function<void(std::size_t, int)>& task,
                 const std::function<bool(std::size_t, int)>& collect, const char* what,
                 const std::function<void(std::size_t)>& waiting, int waiting_seconds) {
  if (workers <= 1) return;
  bool ok = true;
  PoolWork w;
  w.pieces = n;
  w.workers = workers;
  w.before = [&](std::size_t) { return ok; };  // a failed run stops new ones; those running end first
  w.child = task;
  w.collect = collect;
  w.after = [&](std::size_t, int status) { ok = ok && status == 0; };
  w.waiting = waiting;
  w.waiting_seconds = waiting_seconds;
  run_pool(w, what);
  if (!ok)
    throw std::runtime_error(std::string(what) + ": a parallel run failed (set OMP_NUM_THREADS=1 and -j 1 to see it)");
}

}  // namespace dem
