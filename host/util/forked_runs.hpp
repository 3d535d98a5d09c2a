#pragma once
/// Independent pieces of work run side by side in child processes (fork), their results read back through
/// pipes and put in their places: the same results as one at a time, bit for bit, on a host backend of one thread
/// per process (PeriodicLab::set_workers says where that holds).
#include <cstddef>
#include <functional>

namespace dem {

/// Runs task(j, fd) for j = 0 .. n-1, up to `workers` at once, each in a child that writes its result to fd, the next
/// starting as soon as any ends; the parent reads each result as its child ends with collect(j, fd), which returns
/// false where the child's result is cut short (collect must put result j in its place: they come in the order the
/// children end). A child that fails (a cut result, a non-zero exit) stops new ones from starting and throws,
/// naming `what`, once those running have ended. workers <= 1 runs nothing: the caller runs the work itself.
/// `waiting` (optional): called in the parent for each running piece every `waiting_seconds` in which none ends, so
/// that work whose pieces take minutes says how it goes before the first ends.
void forked_runs(std::size_t n, int workers, const std::function<void(std::size_t, int)>& task,
                 const std::function<bool(std::size_t, int)>& collect, const char* what,
                 const std::function<void(std::size_t)>& waiting = {}, int waiting_seconds = 30);

/// n bytes to a child's pipe; a write that fails ends the child (exit status 3), which forked_runs reports.
void put_bytes(int fd, const void* p, std::size_t n);
/// n bytes from a child's pipe; false where the pipe ends first.
bool get_bytes(int fd, void* p, std::size_t n);

}  // namespace dem
