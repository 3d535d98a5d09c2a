#pragma once
/// Whether a run's threads will share their cores with other work. An OpenMP step waits at each barrier for its
/// slowest thread, so a thread whose core another process holds stalls every step: the small S-1 test's first layer,
/// two threads bound to the two cores beside a calibration's two workers, took 30 s for 25 steps it runs in 0.02 s.
#include <string>

namespace dem {

/// This machine's cores (at least 1): what a run's threads and workers are shared out of.
int machine_cores();

/// The note to print before the work, or "" where the threads have the cores to themselves: `load` the machine's
/// 1-minute load average (the other processes': this one has not run yet), `cores` its cores, `threads` this run's,
/// `bind` OMP_PROC_BIND's value (null: unset).
std::string busy_machine_note(double load, int cores, int threads, const char* bind);
/// The same for this machine now (/proc/loadavg and OMP_PROC_BIND; "" where the load cannot be read).
std::string busy_machine_note(int threads);

}  // namespace dem
