#include "host/util/forked_runs.hpp"

#include <sys/wait.h>
#include <unistd.h>

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
  for (std::size_t first = 0; first < n; first += static_cast<std::size_t>(jobs)) {
    const std::size_t last = std::min(n, first + static_cast<std::size_t>(jobs));
    std::vector<std::pair<pid_t, int>> children;
    for (std::size_t j = first; j < last; ++j) {
      int fd[2];
      if (::pipe(fd) != 0) throw std::runtime_error(std::string(what) + ": cannot create a pipe for a parallel run");
      const pid_t pid = ::fork();
      if (pid < 0) throw std::runtime_error(std::string(what) + ": cannot start a parallel run (fork failed)");
      if (pid == 0) {
        ::close(fd[0]);
        task(j, fd[1]);
        std::fflush(nullptr);
        ::_exit(0);  // no atexit handlers, no Kokkos finalize: the parent owns those
      }
      ::close(fd[1]);
      children.emplace_back(pid, fd[0]);
    }
    bool ok = true;
    for (std::size_t c = 0; c < children.size(); ++c) {
      ok = collect(first + c, children[c].second) && ok;
      ::close(children[c].second);
      int status = 0;
      ::waitpid(children[c].first, &status, 0);
      ok = ok && WIFEXITED(status) && WEXITSTATUS(status) == 0;
    }
    if (!ok)
      throw std::runtime_error(std::string(what) + ": a parallel run failed (set OMP_NUM_THREADS=1 and -j 1 to see it)");
  }
}

}  // namespace dem
