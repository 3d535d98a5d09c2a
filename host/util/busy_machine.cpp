#include "host/util/busy_machine.hpp"

#include <cstdio>
#include <cstdlib>
#include <algorithm>
#include <cstring>
#include <fstream>
#include <thread>

namespace dem {

std::string busy_machine_note(double load, int cores, int threads, const char* bind) {
  // Half a core of slack: the load average counts this shell's and the system's short tasks too.
  if (threads <= 1 || !(load + threads > cores + 0.5)) return "";
  const bool bound = bind && *bind && std::strcmp(bind, "false") != 0;
  char note[400];
  std::snprintf(note, sizeof note,
                "note: the machine is busy (load %.1f on %d cores) and this run's %d OpenMP threads%s%s%s share its "
                "cores: each step waits for its slowest thread, so the run can be many times slower than its plan and "
                "ETAs say; run it when the machine is idle, or with OMP_NUM_THREADS=1%s",
                load, cores, threads, bound ? ", bound to cores by OMP_PROC_BIND=" : "", bound ? bind : "",
                bound ? "," : "", bound ? " and OMP_PROC_BIND unset" : "");
  return note;
}

int machine_cores() { return static_cast<int>(std::max(1u, std::thread::hardware_concurrency())); }

std::string busy_machine_note(int threads) {
  double load = 0;
  if (!(std::ifstream("/proc/loadavg") >> load)) return "";
  return busy_machine_note(load, machine_cores(), threads, std::getenv("OMP_PROC_BIND"));
}

}  // namespace dem
