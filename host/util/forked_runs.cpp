#include "host/util/forked_runs.hpp"

#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <iostream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

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

void forked_runs(std::size_t n, int jobs, const std::function<void(std::size_t, int)>& task,
                 const std::function<bool(std::size_t, int)>& collect, const char* what) {
  if (jobs <= 1) return;
  std::cout.flush();
  std::fflush(nullptr);  // a child must not write the parent's buffered output again
  struct Child {
    std::size_t j;
    pid_t pid;
    int fd;
  };
  std::vector<Child> running;
  std::size_t next = 0;
  bool ok = true;
  // The next piece starts as soon as any running one ends, so a slow run holds up only its own slot. A child writes
  // its result as it ends: its pipe turning readable is the sign, and collect then reads the whole result.
  while (running.size() > 0 || (ok && next < n)) {
    while (ok && next < n && running.size() < static_cast<std::size_t>(jobs)) {
      int fd[2];
      if (::pipe(fd) != 0) throw std::runtime_error(std::string(what) + ": cannot create a pipe for a parallel run");
      const pid_t pid = ::fork();
      if (pid < 0) throw std::runtime_error(std::string(what) + ": cannot start a parallel run (fork failed)");
      if (pid == 0) {
        ::close(fd[0]);
        for (const Child& c : running) ::close(c.fd);  // the siblings' pipes are the parent's to read
        task(next, fd[1]);
        std::fflush(nullptr);
        ::_exit(0);  // no atexit handlers, no Kokkos finalize: the parent owns those
      }
      ::close(fd[1]);
      running.push_back({next++, pid, fd[0]});
    }
    std::vector<pollfd> polled;
    for (const Child& c : running) polled.push_back({c.fd, POLLIN, 0});
    if (::poll(polled.data(), polled.size(), -1) < 0) {
      if (errno == EINTR) continue;
      throw std::runtime_error(std::string(what) + ": cannot wait for the parallel runs (poll failed)");
    }
    std::size_t k = 0;
    while (polled[k].revents == 0) ++k;
    const Child c = running[k];
    running.erase(running.begin() + static_cast<std::ptrdiff_t>(k));
    ok = collect(c.j, c.fd) && ok;
    ::close(c.fd);
    int status = 0;
    ::waitpid(c.pid, &status, 0);
    ok = ok && WIFEXITED(status) && WEXITSTATUS(status) == 0;
  }
  if (!ok)
    throw std::runtime_error(std::string(what) + ": a parallel run failed (set OMP_NUM_THREADS=1 and -j 1 to see it)");
}

}  // namespace dem
