#include "periodic_lab.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <stdexcept>
#include <type_traits>

#include <Kokkos_Core.hpp>
#if defined(KOKKOS_ENABLE_OPENMP)
#include <omp.h>
#endif

#include "fnv1a.hpp"
#include "forked_runs.hpp"
#include "periodic_triaxial.hpp"
#include "progress.hpp"
#include "provenance.hpp"

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

PeriodicLab::PeriodicLab(const Config& base, bool verbose, int members, unsigned first_seed, int specimens, int jobs)
    : cfg_(base), members_(std::max(members, 1)), first_seed_(first_seed) {
  set_jobs(jobs);
  pack(std::max(members_, specimens), verbose);
}

void PeriodicLab::pack(int count, bool verbose) {
  specimens_.assign(static_cast<std::size_t>(count), Specimen{});
  auto prepare = [&](std::size_t k) {
    Config c = cfg_;
    c.run.seed = first_seed_ + static_cast<unsigned>(k);
    Specimen& s = specimens_[k];
    prepare_periodic_specimen(c, s.balls, s.cell, verbose && k == 0);
    s.void_ratio = void_ratio_of(s.balls, s.cell);
  };
  if (jobs_ <= 1 || count <= 1) {
    for (std::size_t k = 0; k < specimens_.size(); ++k) prepare(k);
    return;
  }
  // Each specimen in a child, sent back as its ball count, balls (plain data), cell and void ratio.
  static_assert(std::is_trivially_copyable<BallSpec>::value, "BallSpec goes through a pipe as bytes");
  forked_runs(
      specimens_.size(), jobs_,
      [&](std::size_t k, int fd) {
        prepare(k);
        const Specimen& s = specimens_[k];
        const std::size_t n = s.balls.size();
        put_bytes(fd, &n, sizeof n);
        put_bytes(fd, s.balls.data(), n * sizeof(BallSpec));
        put_bytes(fd, s.cell.data(), sizeof s.cell);
        put_bytes(fd, &s.void_ratio, sizeof s.void_ratio);
      },
      [&](std::size_t k, int fd) {
        Specimen& s = specimens_[k];
        std::size_t n = 0;
        if (!get_bytes(fd, &n, sizeof n)) return false;
        s.balls.resize(n);
        return get_bytes(fd, s.balls.data(), n * sizeof(BallSpec)) && get_bytes(fd, s.cell.data(), sizeof s.cell) &&
               get_bytes(fd, &s.void_ratio, sizeof s.void_ratio);
      },
      "specimen preparation");
}

void PeriodicLab::grow_cell(int factor, StateMatch* state) {
  if (factor < 1) throw std::invalid_argument("cell factor " + std::to_string(factor) + " (allowed: 1 or more)");
  cfg_ = larger_cell(cfg_, factor);
  cell_factor_ *= factor;
  // The friction that packs the data's void ratio in a small cell packs a larger one to another.
  if (state && state->tests > 0) {
    MatchPlan plan;
    plan.first_seed = first_seed_;
    plan.specimens = state->specimens;
    plan.jobs = jobs_;
    cfg_.periodic.prep_mu_s = state->prep_mu_s = prep_friction_for(cfg_, state->target, state->reached, false, plan);
  }
  pack(specimens(), false);
}

namespace {
/// The plan's specimens' mean void ratio after their preparation, summed in seed order: packed as a lab packs
/// its specimens, so that the mean matched is the mean of a lab's first specimens, bit for bit.
Real prepared_void_ratio(const Config& cfg, const MatchPlan& plan) {
  const int n = std::max(plan.specimens, 1);
  const PeriodicLab lab(larger_cell(cfg, plan.cell_factor), false, n, plan.first_seed, n, plan.jobs);
  Real sum = 0;
  for (int k = 0; k < n; ++k) sum += lab.prepared_void_ratio(k);
  return sum / static_cast<Real>(n);
}
}  // namespace

MatchPlan match_plan(const Config& base, int jobs) {
  MatchPlan p;
  p.first_seed = base.run.seed;
  p.cell_factor = fixed_cell_factor(base);
  p.jobs = runs_at_once(jobs);
  return p;
}

namespace {
/// The plan's store file of the packing of `c` (friction, cell and seeds named in its hash), "" without a store.
std::string stored_packing_path(const Config& c, const MatchPlan& plan) {
  if (plan.store.empty()) return "";
  const std::string version = program_version();
  std::uint64_t h = fnv1a(version.data(), version.size());
  h = fnv1a(c.fingerprint.data(), c.fingerprint.size(), h);
  const Real v[] = {c.periodic.prep_mu_s, c.box.size[0], c.box.size[1], c.box.size[2]};
  h = fnv1a(v, sizeof v, h);
  const long n[] = {c.particles.count, plan.cell_factor, plan.specimens, static_cast<long>(plan.first_seed)};
  h = fnv1a(n, sizeof n, h);
  return plan.store + "/packing_" + hex16(h) + ".e";
}

/// The plan's mean void ratio after preparation with friction u^2, read from the plan's store where it was kept.
Real void_ratio_at(const Config& base, Real u, const MatchPlan& plan) {
  Config c = base;
  c.periodic.prep_mu_s = u * u;
  const std::string path = stored_packing_path(c, plan);
  Real e = 0;
  if (!path.empty()) {
    std::ifstream in(path, std::ios::binary);
    if (in.read(reinterpret_cast<char*>(&e), sizeof e)) return e;
  }
  e = prepared_void_ratio(c, plan);
  if (!path.empty()) {  // written beside and renamed in, as a run is
    std::filesystem::create_directories(plan.store);
    {
      std::ofstream out(path + ".tmp", std::ios::binary);
      out.write(reinterpret_cast<const char*>(&e), sizeof e);
      if (!out) throw std::runtime_error(path + ".tmp: cannot be written (the calibration's run store)");
    }
    std::filesystem::rename(path + ".tmp", path);
  }
  return e;
}
}  // namespace

std::pair<Real, Real> preparation_reach(const Config& base, const MatchPlan& plan) {
  return {void_ratio_at(base, 0, plan), void_ratio_at(base, 1, plan)};
}

Real prep_friction_for(const Config& base, Real target, Real& reached, bool verbose, const MatchPlan& plan) {
  // Each packing of the plan's specimens takes seconds to minutes: the match reports them (the ends, then the
  // bisection's steps; it may stop early at an end).
  std::optional<Progress> progress;
  if (verbose) progress.emplace("triaxdem: matching the void ratio", 2L + plan.steps);
  long packings = 0;
  auto packed = [&](long count) {
    packings += count;
    if (progress) progress->update(packings, "packings");
  };
  auto at = [&](Real u) {
    const Real e = void_ratio_at(base, u, plan);
    packed(1);
    return e;
  };
  const Real resolution = std::ldexp(Real(1), -plan.steps);
  auto bisect = [&](Real lo, Real hi, Real e_lo, Real e_hi) {
    while (hi - lo > resolution) {
      const Real mid = 0.5 * (lo + hi), e = at(mid);
      (e < target ? lo : hi) = mid;
      (e < target ? e_lo : e_hi) = e;
    }
    const bool low = target - e_lo < e_hi - target;
    reached = low ? e_lo : e_hi;
    return low ? lo * lo : hi * hi;
  };
  if (plan.around >= 0) {
    const Real lo = std::max(Real(0), plan.around - kMatchBracket), hi = std::min(Real(1), plan.around + kMatchBracket);
    const Real e_lo = at(lo), e_hi = at(hi);
    if (e_lo <= target && target <= e_hi) return bisect(lo, hi, e_lo, e_hi);
  }
  auto [e_lo, e_hi] = preparation_reach(base, plan);
  packed(2);
  if (verbose)
    std::printf("triaxdem: preparation friction 0 to 1 packs void ratios %.4f to %.4f (mean of %d specimens); "
                "target %.4f\n", e_lo, e_hi, plan.specimens, target);
  // A state far outside what the cell packs is another material state, not a calibration target (a data void
  // ratio of 4.5 was matched by the loosest packing, 0.87, and calibrated on).
  if (target < e_lo - kMaxStateGap || target > e_hi + kMaxStateGap) {
    char msg[360];
    std::snprintf(msg, sizeof msg, "the data's void ratio %.4f is beyond this cell's reach: preparation friction 0 to "
                  "1 packs it at %.4f to %.4f, and a state more than %.2f outside that range cannot be matched (check "
                  "the data's void_ratio or porosity column)", target, e_lo, e_hi, kMaxStateGap);
    throw DataError(msg);
  }
  if (target <= e_lo) return reached = e_lo, 0;
  if (target >= e_hi) return reached = e_hi, 1;
  return bisect(0, 1, e_lo, e_hi);
}

Config matched_state(const Config& base, const std::vector<MeasuredTest>& tests, StateMatch& m, bool verbose,
                     const MatchPlan& plan) {
  m = StateMatch{};
  Real sum = 0;
  for (const MeasuredTest& t : tests)
    if (std::isfinite(t.void_ratio)) sum += t.void_ratio, ++m.tests;
  if (m.tests == 0) return base;
  m.target = sum / m.tests;
  m.specimens = plan.specimens;
  Config c = base;
  c.periodic.prep_mu_s = m.prep_mu_s = prep_friction_for(base, m.target, m.reached, verbose, plan);
  if (verbose)
    std::printf("triaxdem: the data's void ratio %.4f (mean of %d tests): preparation friction %.4g packs %.4f "
                "(mean of %d specimens)\n",
                m.target, m.tests, m.prep_mu_s, m.reached, m.specimens);
  return c;
}

PeriodicLab::PeriodicLab(const Config& base, bool verbose, int jobs)
    : PeriodicLab(larger_cell(base, fixed_cell_factor(base)), verbose,
                  static_cast<int>(base.calibrate.ensemble == kAutoEnsemble ? base.calibrate.scatter_specimens
                                                                            : base.calibrate.ensemble),
                  base.run.seed, static_cast<int>(base.calibrate.scatter_specimens), jobs) {
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
    auto sim = make_periodic_simulation(sp.balls, sp.cell, m.law, cfg_.solver, cfg_.periodic.boundary);
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

int runs_at_once(int jobs) {
  constexpr bool host = std::is_same<ExecSpace::memory_space, Kokkos::HostSpace>::value;
  return host && ExecSpace().concurrency() == 1 ? std::max(jobs, 1) : 1;
}

int PeriodicLab::set_jobs(int jobs) { return jobs_ = runs_at_once(jobs); }

namespace {

/// The curves of a test through a pipe: row count, then eps_a, q, eps_v (a count of -1: the run blew up).
void send_curves(int fd, const MeasuredTest& t) {
  const long n = std::isfinite(t.q_peak) ? static_cast<long>(t.q.size()) : -1;
  put_bytes(fd, &n, sizeof n);
  put_bytes(fd, &t.void_ratio, sizeof t.void_ratio);
  for (const std::vector<Real>* v : {&t.eps_a, &t.q, &t.eps_v})
    if (n > 0) put_bytes(fd, v->data(), sizeof(Real) * v->size());
}

bool receive_curves(int fd, MeasuredTest& t) {
  long n = 0;
  if (!get_bytes(fd, &n, sizeof n) || !get_bytes(fd, &t.void_ratio, sizeof t.void_ratio)) return false;
  if (n < 0) {
    mark_failed(t);
    return true;
  }
  for (std::vector<Real>* v : {&t.eps_a, &t.q, &t.eps_v}) {
    v->resize(static_cast<std::size_t>(n));
    if (n > 0 && !get_bytes(fd, v->data(), sizeof(Real) * v->size())) return false;
  }
  summarise(t);
  return true;
}

}  // namespace

void PeriodicLab::set_run_store(std::string folder) { store_ = std::move(folder); }

std::string PeriodicLab::stored_path(const Model& m, const Case& c) const {
  if (store_.empty()) return "";
  const std::string version = program_version();
  std::uint64_t h = fnv1a(version.data(), version.size());
  h = fnv1a(cfg_.fingerprint.data(), cfg_.fingerprint.size(), h);
  h = fnv1a(&m.law, sizeof m.law, h);  // Reals only: no padding
  h = fnv1a(&m.membrane, sizeof m.membrane, h);
  h = fnv1a(&c.sigma3, sizeof c.sigma3, h);
  const Specimen& sp = specimens_.at(static_cast<std::size_t>(c.member));
  for (const BallSpec& b : sp.balls) {
    const Real v[] = {b.x.x, b.x.y, b.x.z, b.v.x, b.v.y, b.v.z, b.w.x, b.w.y, b.w.z, b.radius, b.density};
    h = fnv1a(v, sizeof v, h);
    h = fnv1a(&b.material, sizeof b.material, h);
  }
  h = fnv1a(sp.cell.data(), sizeof(Real) * sp.cell.size(), h);
  return store_ + "/" + hex16(h) + ".run";
}

namespace {
/// A stored run's curves (send_curves' bytes), or false where there is none or it is cut short.
bool read_stored(const std::string& path, MeasuredTest& t) {
  if (path.empty()) return false;
  const int fd = ::open(path.c_str(), O_RDONLY);
  if (fd < 0) return false;
  const bool ok = receive_curves(fd, t);
  ::close(fd);
  return ok;
}

/// Writes a run's curves beside their place and renames them in: a killed calibration leaves whole files only.
void store_run(const std::string& path, const MeasuredTest& t) {
  if (path.empty()) return;
  std::filesystem::create_directories(std::filesystem::path(path).parent_path());  // at the first run
  const std::string tmp = path + ".tmp";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fd < 0) throw std::runtime_error(tmp + ": cannot be written (the calibration's run store)");
  send_curves(fd, t);
  ::close(fd);
  std::filesystem::rename(tmp, path);
}
}  // namespace

std::vector<MeasuredTest> PeriodicLab::run_cases(const Model& m, const std::vector<Case>& cases) {
  std::vector<MeasuredTest> out(cases.size());
  std::optional<Progress> progress;
  if (!progress_label_.empty()) progress.emplace(progress_label_, static_cast<long>(cases.size()));
  long done = 0;
  const auto one_done = [&]() {
    if (progress) progress->update(++done, "runs");
  };
  std::vector<std::string> paths(cases.size());
  std::vector<std::size_t> todo;  // the cases not in the store
  for (std::size_t j = 0; j < cases.size(); ++j) {
    paths[j] = stored_path(m, cases[j]);
    out[j].material = cases[j].material;
    out[j].sigma3 = cases[j].sigma3;
    if (read_stored(paths[j], out[j])) {
      ++stored_read_;
      ++runs_;  // a run of the search, read: the counts a resumed search reports are those it reported
      one_done();
    } else {
      out[j] = MeasuredTest{};
      todo.push_back(j);
    }
  }
  if (jobs_ <= 1 || todo.size() <= 1) {
    for (const std::size_t j : todo) {
      out[j] = run(m, cases[j].sigma3, cases[j].material, cases[j].member);
      store_run(paths[j], out[j]);
      one_done();
    }
    return out;
  }
  const auto t0 = std::chrono::steady_clock::now();
  forked_runs(
      todo.size(), jobs_,
      [&](std::size_t k, int fd) {
        const Case& c = cases[todo[k]];
        send_curves(fd, run(m, c.sigma3, c.material, c.member));
      },
      [&](std::size_t k, int fd) {
        const std::size_t j = todo[k];
        out[j].material = cases[j].material;
        out[j].sigma3 = cases[j].sigma3;
        const bool received = receive_curves(fd, out[j]);
        if (received) store_run(paths[j], out[j]);
        one_done();
        return received;
      },
      "calibration");
  runs_ += static_cast<long>(todo.size());
  seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

Ensemble PeriodicLab::run_ensemble(const Model& m, const std::vector<MeasuredTest>& like, bool all) {
  const std::size_t M = all ? specimens_.size() : static_cast<std::size_t>(members_);
  std::vector<Case> cases;  // case j: test j / M on member j % M
  for (std::size_t j = 0; j < like.size() * M; ++j)
    cases.push_back({like[j / M].material, like[j / M].sigma3, static_cast<int>(j % M)});
  const std::vector<MeasuredTest> done = run_cases(m, cases);
  Ensemble out(like.size());
  for (std::size_t j = 0; j < done.size(); ++j) out[j / M].push_back(done[j]);
  return out;
}

std::vector<MeasuredTest> PeriodicLab::run_each(const Model& m, const std::vector<MeasuredTest>& like) {
  std::vector<Case> cases;
  for (std::size_t j = 0; j < like.size(); ++j)
    cases.push_back({like[j].material, like[j].sigma3, static_cast<int>(j % static_cast<std::size_t>(members_))});
  return run_cases(m, cases);
}

}  // namespace dem
