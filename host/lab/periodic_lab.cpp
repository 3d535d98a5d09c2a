#include "host/lab/periodic_lab.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <type_traits>

#include "host/triax/periodic_triaxial.hpp"
#include "host/util/forked_runs.hpp"
#include "host/util/progress.hpp"

namespace dem {

namespace {

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

void PeriodicLab::count_runs(std::size_t n, std::chrono::steady_clock::time_point t0) {
  runs_ += static_cast<long>(n);
  const double s = seconds_since(t0);
  seconds_ += s;
  time_so_far.runs += s;
  time_so_far.ran += static_cast<long>(n);
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
