#include "host/lab/periodic_lab.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <stdexcept>
#include <type_traits>

#include <Kokkos_Core.hpp>
#if defined(KOKKOS_ENABLE_OPENMP)
#include <omp.h>
#endif

#include "host/util/fnv1a.hpp"
#include "host/util/forked_runs.hpp"
#include "host/triax/periodic_triaxial.hpp"
#include "host/util/progress.hpp"
#include "host/util/ranks.hpp"
#include "host/lab/run_store.hpp"

namespace dem {

namespace {

/// A run that produced no test (a blow-up): every quantity NaN, counted as missing by residuals().
void mark_failed(TriaxialTest& t) {
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

PeriodicLab::PeriodicLab(const Config& base, bool verbose, int members, unsigned first_seed, int specimens, int workers)
    : cfg_(base), members_(std::max(members, 1)), first_seed_(first_seed) {
  set_workers(workers);
  set_batch(base.calibrate.batch);
  pack(std::max(members_, specimens), verbose);
}

int PeriodicLab::set_batch(long batch) {
  if (batch == kAutoBatch) batch = kOnDevice ? 4096 : 1;
  if (cfg_.periodic.boundary == CellBoundary::walls) batch = 1;  // CellBatch takes periodic cells
  return batch_ = static_cast<int>(std::max(1L, batch));
}

namespace {
LabTime time_so_far;
}  // namespace

LabTime lab_time() { return time_so_far; }

void PeriodicLab::pack(int count, bool verbose) {
  const auto t0 = std::chrono::steady_clock::now();
  struct Clock {  // counted however the packing ends
    std::chrono::steady_clock::time_point t0;
    ~Clock() { time_so_far.packing += seconds_since(t0); }
  } clock{t0};
  specimens_.assign(static_cast<std::size_t>(count), PackedCell{});
  if (batch_ > 1 && count > 1) {
    if (verbose)
      std::printf("triaxdem: preparation: %d specimens of %ld balls, side by side in batches of up to %d\n", count,
                  cfg_.particles.count, batch_);
    for (int first = 0; first < count; first += batch_) {
      std::vector<Config> cfgs;
      for (int k = first; k < std::min(count, first + batch_); ++k) {
        cfgs.push_back(cfg_);
        cfgs.back().run.seed = first_seed_ + static_cast<unsigned>(k);
      }
      const std::vector<PreparedCell> made = prepare_periodic_specimens(cfgs);
      for (std::size_t j = 0; j < made.size(); ++j) {
        PackedCell& s = specimens_[static_cast<std::size_t>(first) + j];
        s.balls = made[j].balls;
        s.cell = made[j].cell;
        s.void_ratio = void_ratio_of(s.balls, s.cell);
      }
    }
    return;
  }
  auto prepare = [&](std::size_t k) {
    Config c = cfg_;
    c.run.seed = first_seed_ + static_cast<unsigned>(k);
    PackedCell& s = specimens_[k];
    prepare_periodic_specimen(c, s.balls, s.cell, verbose && k == 0);
    s.void_ratio = void_ratio_of(s.balls, s.cell);
  };
  if (workers_ <= 1 || count <= 1) {
    for (std::size_t k = 0; k < specimens_.size(); ++k) prepare(k);
    return;
  }
  // Each specimen in a child, sent back as its ball count, balls (plain data), cell and void ratio.
  static_assert(std::is_trivially_copyable<BallSpec>::value, "BallSpec goes through a pipe as bytes");
  forked_runs(
      specimens_.size(), workers_,
      [&](std::size_t k, int fd) {
        prepare(k);
        const PackedCell& s = specimens_[k];
        const std::size_t n = s.balls.size();
        put_bytes(fd, &n, sizeof n);
        put_bytes(fd, s.balls.data(), n * sizeof(BallSpec));
        put_bytes(fd, s.cell.data(), sizeof s.cell);
        put_bytes(fd, &s.void_ratio, sizeof s.void_ratio);
      },
      [&](std::size_t k, int fd) {
        PackedCell& s = specimens_[k];
        std::size_t n = 0;
        if (!get_bytes(fd, &n, sizeof n)) return false;
        s.balls.resize(n);
        return get_bytes(fd, s.balls.data(), n * sizeof(BallSpec)) && get_bytes(fd, s.cell.data(), sizeof s.cell) &&
               get_bytes(fd, &s.void_ratio, sizeof s.void_ratio);
      },
      "specimen preparation");
}

StateMatch PeriodicLab::grow_cell(int factor, const StateMatch& state) {
  if (factor < 1) throw std::invalid_argument("cell factor " + std::to_string(factor) + " (allowed: 1 or more)");
  cfg_ = larger_cell(cfg_, factor);
  cell_factor_ *= factor;
  // The friction that packs the data's void ratio in a small cell packs a larger one to another.
  StateMatch grown = state;
  if (state.tests > 0) {
    MatchPlan plan;
    plan.first_seed = first_seed_;
    plan.specimens = state.specimens;
    plan.workers = workers_;
    cfg_.periodic.prep_mu_s = grown.prep_mu_s = prep_friction_for(cfg_, state.target, grown.reached, false, plan);
  }
  pack(specimens(), false);
  return grown;
}

MatchPlan match_plan(const Config& base, int workers) {
  MatchPlan p;
  p.first_seed = base.run.seed;
  p.cell_factor = fixed_cell_factor(base);
  p.workers = runs_at_once(workers);
  return p;
}

PeriodicLab::PeriodicLab(const Config& base, bool verbose, int workers)
    : PeriodicLab(larger_cell(base, fixed_cell_factor(base)), verbose,
                  static_cast<int>(base.calibrate.ensemble == kAutoEnsemble ? base.calibrate.scatter_specimens
                                                                            : base.calibrate.ensemble),
                  base.run.seed, static_cast<int>(base.calibrate.scatter_specimens), workers) {
  cell_factor_ = fixed_cell_factor(base);
}

void PeriodicLab::set_members(int k) {
  if (k < 1 || k > specimens())
    throw std::invalid_argument("ensemble of " + std::to_string(k) + " specimens (allowed: 1 to " +
                                std::to_string(specimens()) + ")");
  members_ = k;
}

PeriodicTriaxialParams PeriodicLab::test_params(const Model& m, Real sigma3) const {
  PeriodicTriaxialParams p = cfg_.periodic.triax;
  p.sigma3 = sigma3;
  p.membrane_stiffness = m.membrane;
  p.verbose = false;
  p.snapshot_strains.clear();
  return p;
}

TriaxialTest PeriodicLab::run(const Model& m, Real sigma3, const std::string& material, int member) {
  const auto t0 = std::chrono::steady_clock::now();
  const PackedCell& sp = specimens_.at(static_cast<std::size_t>(member));
  TriaxialTest t;
  const PeriodicTriaxialParams p = test_params(m, sigma3);
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
  const double s = seconds_since(t0);
  seconds_ += s;
  time_so_far.runs += s;
  ++time_so_far.ran;
  return t;
}

void prepare_parallel_runs(int workers) {
#if defined(KOKKOS_ENABLE_OPENMP)
  if (workers > 1) omp_set_num_threads(1);
#else
  (void)workers;
#endif
}

int runs_at_once(int workers) {
  // Spread over ranks, the pools' pieces go to the other ranks, one at a time each (ranks.hpp), in child processes:
  // a GPU build cannot fork once its device has started, so there every rank runs every piece itself.
  if (ranks::spread()) return kOnDevice ? 1 : std::max(2, ranks::size() - 1);
  return !kOnDevice && ExecSpace().concurrency() == 1 ? std::max(workers, 1) : 1;
}

int PeriodicLab::set_workers(int workers) { return workers_ = runs_at_once(workers); }

namespace {

/// The curves of a test as bytes to `put(pointer, count)`: row count, void ratio, then eps_a, q, eps_v (a count of
/// -1: the run blew up). Through a child's pipe (send_curves) and into the run store.
template <class Put>
void put_curves(const TriaxialTest& t, Put put) {
  const long n = std::isfinite(t.q_peak) ? static_cast<long>(t.q.size()) : -1;
  put(&n, sizeof n);
  put(&t.void_ratio, sizeof t.void_ratio);
  for (const std::vector<Real>* v : {&t.eps_a, &t.q, &t.eps_v})
    if (n > 0) put(v->data(), sizeof(Real) * v->size());
}

void send_curves(int fd, const TriaxialTest& t) {
  put_curves(t, [fd](const void* p, std::size_t n) { put_bytes(fd, p, n); });
}

bool receive_curves(int fd, TriaxialTest& t) {
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
  std::uint64_t h = store_hash(cfg_);
  h = fnv1a(&m.law, sizeof m.law, h);  // Reals only: no padding
  h = fnv1a(&m.membrane, sizeof m.membrane, h);
  h = fnv1a(&c.sigma3, sizeof c.sigma3, h);
  const PackedCell& sp = specimens_.at(static_cast<std::size_t>(c.member));
  for (const BallSpec& b : sp.balls) {
    const Real v[] = {b.x.x, b.x.y, b.x.z, b.v.x, b.v.y, b.v.z, b.w.x, b.w.y, b.w.z, b.radius, b.density};
    h = fnv1a(v, sizeof v, h);
    h = fnv1a(&b.material, sizeof b.material, h);
  }
  h = fnv1a(sp.cell.data(), sizeof(Real) * sp.cell.size(), h);
  return store_ + "/" + hex16(h) + ".run";
}

namespace {
/// A run's curves into the store (put_curves' bytes, as through a pipe).
void store_run(const std::string& path, const TriaxialTest& t) {
  if (path.empty()) return;
  std::string bytes;
  put_curves(t, [&](const void* p, std::size_t n) { bytes.append(static_cast<const char*>(p), n); });
  write_stored(path, bytes);
}
}  // namespace

std::vector<TriaxialTest> PeriodicLab::run_cases(const Model& m, const std::vector<Case>& cases) {
  std::vector<TriaxialTest> out = run_or_read(m, cases);
  for (const TriaxialTest& t : out)
    if (!std::isfinite(t.q_peak)) ++failed_, failed_sigma3_ = std::max(failed_sigma3_, t.sigma3);
  return out;
}

std::vector<TriaxialTest> PeriodicLab::run_or_read(const Model& m, const std::vector<Case>& cases) {
  std::vector<TriaxialTest> out(cases.size());
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
    if (read_stored(paths[j], [&](int fd) { return receive_curves(fd, out[j]); })) {
      ++stored_read_;
      ++runs_;  // a run of the search, read: the counts a resumed search reports are those it reported
      one_done();
    } else {
      out[j] = TriaxialTest{};
      todo.push_back(j);
    }
  }
  if (batch_ > 1 && todo.size() > 1) {
    const auto t0 = std::chrono::steady_clock::now();
    for (std::size_t first = 0; first < todo.size(); first += static_cast<std::size_t>(batch_)) {
      std::vector<Case> chunk;
      for (std::size_t k = first; k < std::min(todo.size(), first + static_cast<std::size_t>(batch_)); ++k)
        chunk.push_back(cases[todo[k]]);
      const std::vector<TriaxialTest> done = run_batch(m, chunk);
      for (std::size_t k = 0; k < done.size(); ++k) {
        const std::size_t j = todo[first + k];
        out[j] = done[k];
        store_run(paths[j], out[j]);
        one_done();
      }
    }
    count_runs(todo.size(), t0);
    return out;
  }
  if (workers_ <= 1 || todo.size() <= 1) {
    for (const std::size_t j : todo) {
      out[j] = run(m, cases[j].sigma3, cases[j].material, cases[j].member);
      store_run(paths[j], out[j]);
      one_done();
    }
    return out;
  }
  const auto t0 = std::chrono::steady_clock::now();
  forked_runs(
      todo.size(), workers_,
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
  count_runs(todo.size(), t0);
  return out;
}

void PeriodicLab::count_runs(std::size_t n, std::chrono::steady_clock::time_point t0) {
  runs_ += static_cast<long>(n);
  const double s = seconds_since(t0);
  seconds_ += s;
  time_so_far.runs += s;
  time_so_far.ran += static_cast<long>(n);
}

std::vector<TriaxialTest> PeriodicLab::run_batch(const Model& m, const std::vector<Case>& cases) {
  std::vector<std::unique_ptr<Simulation>> made;
  std::vector<Simulation*> sims;
  std::vector<PeriodicTriaxialParams> prms;
  for (const Case& c : cases) {
    const PackedCell& sp = specimens_.at(static_cast<std::size_t>(c.member));
    made.push_back(make_periodic_simulation(sp.balls, sp.cell, m.law, cfg_.solver, cfg_.periodic.boundary));
    sims.push_back(made.back().get());
    prms.push_back(test_params(m, c.sigma3));
  }
  const std::vector<BatchedTest> runs = run_periodic_batch(sims, prms);
  std::vector<TriaxialTest> out(cases.size());
  for (std::size_t j = 0; j < cases.size(); ++j) {
    // As run() meets them: a consolidation that does not converge is the job's error, a blow-up a missing test.
    if (!runs[j].failure.empty()) throw std::runtime_error(runs[j].failure);
    TriaxialTest& t = out[j];
    if (runs[j].blowup.empty()) {
      t = summarised(runs[j].result.series, cases[j].sigma3);
      t.void_ratio = runs[j].result.void_ratio0;
    } else {
      t.sigma3 = cases[j].sigma3;
      mark_failed(t);
    }
    t.material = cases[j].material;
  }
  return out;
}

Ensemble PeriodicLab::run_ensemble(const Model& m, const std::vector<TriaxialTest>& like, bool all) {
  const std::size_t M = all ? specimens_.size() : static_cast<std::size_t>(members_);
  std::vector<Case> cases;  // case j: test j / M on member j % M
  for (std::size_t j = 0; j < like.size() * M; ++j)
    cases.push_back({like[j / M].material, like[j / M].sigma3, static_cast<int>(j % M)});
  const std::vector<TriaxialTest> done = run_cases(m, cases);
  Ensemble out(like.size());
  for (std::size_t j = 0; j < done.size(); ++j) out[j / M].push_back(done[j]);
  return out;
}

std::vector<TriaxialTest> PeriodicLab::run_each(const Model& m, const std::vector<TriaxialTest>& like) {
  std::vector<Case> cases;
  for (std::size_t j = 0; j < like.size(); ++j)
    cases.push_back({like[j].material, like[j].sigma3, static_cast<int>(j % static_cast<std::size_t>(members_))});
  return run_cases(m, cases);
}

}  // namespace dem
