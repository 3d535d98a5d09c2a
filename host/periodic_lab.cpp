#include "periodic_lab.hpp"

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

/// Cell volume over the balls' volume, less one.
Real void_ratio_of(const std::vector<BallSpec>& balls, const std::array<Real, 3>& cell) {
  return cell[0] * cell[1] * cell[2] / solid_volume(balls) - 1;
}

}  // namespace

// ---------------------------------------------------------------------------------------------------
// Simulator

Model model_of(const Config& cfg) {
  Model m;
  m.law = cfg.ball;
  m.membrane = cfg.periodic.triax.membrane_stiffness;
  return m;
}

namespace {
/// The config's fixed cell factor; an "auto" cell starts as the config's own (1).
int fixed_cell_factor(const Config& c) { return static_cast<int>(std::max(c.calibrate.cell_factor, 1L)); }
}  // namespace

Config larger_cell(const Config& base, int factor) {
  Config c = base;
  c.particles.count *= factor;
  for (Real& side : c.box.size) side *= std::cbrt(static_cast<Real>(factor));
  return c;
}

PeriodicLab::PeriodicLab(const Config& base, bool verbose, int members, unsigned first_seed, int specimens)
    : cfg_(base), members_(std::max(members, 1)), first_seed_(first_seed) {
  pack(std::max(members_, specimens), verbose);
}

void PeriodicLab::pack(int count, bool verbose) {
  specimens_.clear();
  for (int k = 0; k < count; ++k) {
    Config c = cfg_;
    c.run.seed = first_seed_ + static_cast<unsigned>(k);
    Specimen s;
    prepare_periodic_specimen(c, s.balls, s.cell, verbose && k == 0);
    s.void_ratio = void_ratio_of(s.balls, s.cell);
    specimens_.push_back(std::move(s));
  }
}

void PeriodicLab::grow_cell(int factor) {
  if (factor < 1) throw std::invalid_argument("cell factor " + std::to_string(factor) + " (allowed: 1 or more)");
  cfg_ = larger_cell(cfg_, factor);
  cell_factor_ *= factor;
  pack(specimens(), false);
}

namespace {
Real prepared_void_ratio(const Config& cfg) {
  std::vector<BallSpec> balls;
  std::array<Real, 3> cell{};
  prepare_periodic_specimen(cfg, balls, cell, false);
  return void_ratio_of(balls, cell);
}
}  // namespace

Real prep_friction_for(const Config& base, Real target, Real& reached, bool verbose, int steps) {
  Config c = base;
  auto at = [&](Real u) {
    c.periodic.prep_mu_s = u * u;
    return prepared_void_ratio(c);
  };
  Real lo = 0, hi = 1, e_lo = at(lo), e_hi = at(hi);
  if (verbose)
    std::printf("triaxdem: preparation friction 0 to 1 packs void ratios %.4f to %.4f; target %.4f\n", e_lo, e_hi,
                target);
  if (target <= e_lo) return reached = e_lo, 0;
  if (target >= e_hi) return reached = e_hi, 1;
  for (int k = 0; k < steps; ++k) {
    const Real mid = 0.5 * (lo + hi), e = at(mid);
    (e < target ? lo : hi) = mid;
    (e < target ? e_lo : e_hi) = e;
  }
  const bool low = target - e_lo < e_hi - target;
  reached = low ? e_lo : e_hi;
  return low ? lo * lo : hi * hi;
}

Config matched_state(const Config& base, const std::vector<MeasuredTest>& tests, StateMatch& m, bool verbose,
                     int steps) {
  Real sum = 0;
  for (const MeasuredTest& t : tests)
    if (std::isfinite(t.void_ratio)) sum += t.void_ratio, ++m.tests;
  if (m.tests == 0) return base;
  m.target = sum / m.tests;
  Config c = base;
  c.periodic.prep_mu_s = m.prep_mu_s = prep_friction_for(base, m.target, m.reached, verbose, steps);
  if (verbose)
    std::printf("triaxdem: the data's void ratio %.4f (mean of %d tests): preparation friction %.4g packs %.4f\n",
                m.target, m.tests, m.prep_mu_s, m.reached);
  return c;
}

PeriodicLab::PeriodicLab(const Config& base, bool verbose)
    : PeriodicLab(larger_cell(base, fixed_cell_factor(base)), verbose,
                  static_cast<int>(base.calibrate.ensemble == kAutoEnsemble ? base.calibrate.scatter_specimens
                                                                            : base.calibrate.ensemble),
                  base.run.seed, static_cast<int>(base.calibrate.scatter_specimens)) {
  cell_factor_ = fixed_cell_factor(base);
}

void PeriodicLab::set_members(int k) {
  if (k < 1 || k > specimens())
    throw std::invalid_argument("ensemble of " + std::to_string(k) + " specimens (allowed: 1 to " +
                                std::to_string(specimens()) + ")");
  members_ = k;
}

MeasuredTest PeriodicLab::run(const Model& m, Real sigma3, const std::string& material, int member) {
  const auto t0 = std::chrono::steady_clock::now();
  const Specimen& sp = specimens_.at(static_cast<std::size_t>(member));
  MeasuredTest t;
  PeriodicTriaxialParams p = cfg_.periodic.triax;
  p.sigma3 = sigma3;
  p.membrane_stiffness = m.membrane;
  p.verbose = false;
  p.snapshot_strains.clear();
  try {
    auto sim = make_periodic_simulation(sp.balls, sp.cell, m.law, cfg_.solver);
    const PeriodicTriaxialResult r = run_periodic_triaxial(*sim, p);
    t = summarised(r.series, sigma3);
    t.void_ratio = r.void_ratio0;
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
  put(&t.void_ratio, sizeof t.void_ratio);
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
  if (!get(&n, sizeof n) || !get(&t.void_ratio, sizeof t.void_ratio)) return false;
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

Ensemble PeriodicLab::run_ensemble(const Model& m, const std::vector<MeasuredTest>& like, bool all) {
  const std::size_t M = all ? specimens_.size() : static_cast<std::size_t>(members_);
  const std::size_t N = like.size() * M;  // run j: test j / M, member j % M
  Ensemble out(like.size());
  if (jobs_ <= 1 || N <= 1) {
    for (std::size_t j = 0; j < N; ++j)
      out[j / M].push_back(run(m, like[j / M].sigma3, like[j / M].material, static_cast<int>(j % M)));
    return out;
  }
  const auto t0 = std::chrono::steady_clock::now();
  std::cout.flush();
  std::fflush(nullptr);  // a child must not write the parent's buffered output again
  for (std::size_t first = 0; first < N; first += static_cast<std::size_t>(jobs_)) {
    const std::size_t last = std::min(N, first + static_cast<std::size_t>(jobs_));
    std::vector<std::pair<pid_t, int>> children;
    for (std::size_t j = first; j < last; ++j) {
      int fd[2];
      if (::pipe(fd) != 0) throw std::runtime_error("calibration: cannot create a pipe for a parallel run");
      const pid_t pid = ::fork();
      if (pid < 0) throw std::runtime_error("calibration: cannot start a parallel run (fork failed)");
      if (pid == 0) {
        ::close(fd[0]);
        send_curves(fd[1], run(m, like[j / M].sigma3, like[j / M].material, static_cast<int>(j % M)));
        ::_exit(0);  // no atexit handlers, no Kokkos finalize: the parent owns those
      }
      ::close(fd[1]);
      children.emplace_back(pid, fd[0]);
    }
    bool ok = true;
    for (std::size_t c = 0; c < children.size(); ++c) {
      const MeasuredTest& like_it = like[(first + c) / M];
      MeasuredTest t;
      t.material = like_it.material;
      t.sigma3 = like_it.sigma3;
      ok = receive_curves(children[c].second, t) && ok;
      ::close(children[c].second);
      int status = 0;
      ::waitpid(children[c].first, &status, 0);
      ok = ok && WIFEXITED(status) && WEXITSTATUS(status) == 0;
      out[(first + c) / M].push_back(t);
    }
    if (!ok) throw std::runtime_error("calibration: a parallel run failed (set OMP_NUM_THREADS=1 and -j 1 to see it)");
  }
  runs_ += static_cast<long>(N);
  seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace dem
