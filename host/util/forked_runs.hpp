#pragma once
/// Independent pieces of work run side by side in child processes (fork), their results read back through
/// pipes in a fixed order: the same results as one at a time, bit for bit, on a host backend of one thread per
/// process (PeriodicLab::set_jobs says where that holds).
#include <cstddef>
#include <functional>

namespace dem {

/// Runs task(j, fd) for j = 0 .. n-1, up to `jobs` at once, each in a child that writes its result to fd; the
/// parent reads them in order of j with collect(j, fd), which returns false where the child's result is cut
/// short. A child that fails (a cut result, a non-zero exit) throws, naming `what`, after all children of its
/// round have ended. jobs <= 1 runs nothing: the caller runs the work itself.
void forked_runs(std::size_t n, int jobs, const std::function<void(std::size_t, int)>& task,
                 const std::function<bool(std::size_t, int)>& collect, const char* what);

/// n bytes to a child's pipe; a write that fails ends the child (exit status 3), which forked_runs reports.
void put_bytes(int fd, const void* p, std::size_t n);
/// n bytes from a child's pipe; false where the pipe ends first.
bool get_bytes(int fd, void* p, std::size_t n);

}  // namespace dem
