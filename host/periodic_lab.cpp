#include "calibrate.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <limits>
#include <stdexcept>
#include <type_traits>

#include <Kokkos_Core.hpp>
#if defined(KOKKOS_ENABLE_OPENMP)
#include <omp.h>
#endif

#include "periodic_triaxial.hpp"

namespace dem {

namespace {

/// A run that produced no test (a blow-up): every quantity NaN, counted as missing by residuals().
void mark_failed(MeasuredTest& t) {
  t.q_peak = t.eps_a_peak = t.q_end = t.max_dilatancy = t.e_ini = t.q_1pct = t.q_3pct =
      std::numeric_limits<Real>::quiet_NaN();
}

}  // namespace

// ---------------------------------------------------------------------------------------------------
// Simulator

PeriodicLab::PeriodicLab(const Config& base, bool verbose) : cfg_(base) {
  prepare_periodic_specimen(cfg_, balls_, cell_, verbose);
}

MeasuredTest PeriodicLab::run(const Model& m, Real sigma3, const std::string& material) {
  const auto t0 = std::chrono::steady_clock::now();
  MeasuredTest t;
  PeriodicTriaxialParams p = cfg_.periodic.triax;
  p.sigma3 = sigma3;
  p.membrane_stiffness = m.membrane;
  p.verbose = false;
  p.snapshot_strains.clear();
  try {
    auto sim = make_periodic_simulation(balls_, cell_, m.law, cfg_.solver);
    t = summarised(run_periodic_triaxial(*sim, p).series, sigma3);
  } catch (const BlowUp&) {
    t.sigma3 = sigma3;
    mark_failed(t);
  }
  t.material = material;
  ++runs_;
  seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return t;
}

void prepare_parallel_runs(int jobs) {
#if defined(KOKKOS_ENABLE_OPENMP)
  if (jobs > 1) omp_set_num_threads(1);
#else
  (void)jobs;
#endif
}

int PeriodicLab::set_jobs(int jobs) {
  constexpr bool host = std::is_same<ExecSpace::memory_space, Kokkos::HostSpace>::value;
  jobs_ = host && ExecSpace().concurrency() == 1 ? std::max(jobs, 1) : 1;
  return jobs_;
}

namespace {

/// The curves of a test through a pipe: row count, then eps_a, q, eps_v (a count of -1: the run blew up).
void send_curves(int fd, const MeasuredTest& t) {
  auto put = [&](const void* p, std::size_t n) {
    for (const char* c = static_cast<const char*>(p); n > 0;) {
      const ssize_t w = ::write(fd, c, n);
      if (w <= 0) ::_exit(3);
      c += w, n -= static_cast<std::size_t>(w);
    }
  };
  const long n = std::isfinite(t.q_peak) ? static_cast<long>(t.q.size()) : -1;
  put(&n, sizeof n);
  for (const std::vector<Real>* v : {&t.eps_a, &t.q, &t.eps_v})
    if (n > 0) put(v->data(), sizeof(Real) * v->size());
}

bool receive_curves(int fd, MeasuredTest& t) {
  auto get = [&](void* p, std::size_t n) {
    for (char* c = static_cast<char*>(p); n > 0;) {
      const ssize_t r = ::read(fd, c, n);
      if (r <= 0) return false;
      c += r, n -= static_cast<std::size_t>(r);
    }
    return true;
  };
  long n = 0;
  if (!get(&n, sizeof n)) return false;
  if (n < 0) {
    mark_failed(t);
    return true;
  }
  for (std::vector<Real>* v : {&t.eps_a, &t.q, &t.eps_v}) {
    v->resize(static_cast<std::size_t>(n));
    if (n > 0 && !get(v->data(), sizeof(Real) * v->size())) return false;
  }
  summarise(t);
  return true;
}

}  // namespace

std::vector<MeasuredTest> PeriodicLab::run_all(const Model& m, const std::vector<MeasuredTest>& like) {
  std::vector<MeasuredTest> out;
  if (jobs_ <= 1 || like.size() <= 1) {
    for (const MeasuredTest& t : like) out.push_back(run(m, t.sigma3, t.material));
    return out;
  }
  const auto t0 = std::chrono::steady_clock::now();
  std::cout.flush();
  std::fflush(nullptr);  // a child must not write the parent's buffered output again
  for (std::size_t first = 0; first < like.size(); first += static_cast<std::size_t>(jobs_)) {
    const std::size_t last = std::min(like.size(), first + static_cast<std::size_t>(jobs_));
    std::vector<std::pair<pid_t, int>> children;
    for (std::size_t k = first; k < last; ++k) {
      int fd[2];
      if (::pipe(fd) != 0) throw std::runtime_error("calibration: cannot create a pipe for a parallel run");
      const pid_t pid = ::fork();
      if (pid < 0) throw std::runtime_error("calibration: cannot start a parallel run (fork failed)");
      if (pid == 0) {
        ::close(fd[0]);
        send_curves(fd[1], run(m, like[k].sigma3, like[k].material));
        ::_exit(0);  // no atexit handlers, no Kokkos finalize: the parent owns those
      }
      ::close(fd[1]);
      children.emplace_back(pid, fd[0]);
    }
    bool ok = true;
    for (std::size_t c = 0; c < children.size(); ++c) {
      MeasuredTest t;
      t.material = like[first + c].material;
      t.sigma3 = like[first + c].sigma3;
      ok = receive_curves(children[c].second, t) && ok;
      ::close(children[c].second);
      int status = 0;
      ::waitpid(children[c].first, &status, 0);
      ok = ok && WIFEXITED(status) && WEXITSTATUS(status) == 0;
      out.push_back(t);
    }
    if (!ok) throw std::runtime_error("calibration: a parallel run failed (set OMP_NUM_THREADS=1 and -j 1 to see it)");
  }
  runs_ += static_cast<long>(like.size());
  seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace dem
