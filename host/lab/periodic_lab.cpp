#include "host/lab/periodic_lab.hpp"
#include "host/lab/run_cost.hpp"

#include <chrono>
#include <cmath>
#include <limits>
#include <cstdio>
#include <stdexcept>
#include <optional>

#include "host/triax/periodic_triaxial.hpp"
#include "host/util/forked_runs.hpp"
#include "host/util/progress.hpp"
#include "host/lab/wall_layer.hpp"

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
    : cfg_(base), members_(std::max(members, 1)), first_seed_(first_seed), verbose_(verbose) {
  set_workers(workers);
  set_batch(base.calibrate.batch);
  pack(std::max(members_, specimens), verbose);
}

int PeriodicLab::set_batch(long batch) { return batch_ = batch_in_effect(batch, cfg_); }

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
  std::vector<Config> cfgs(specimens_.size(), cfg_);
  std::vector<std::size_t> todo;  // the specimens the store does not hold
  for (std::size_t k = 0; k < cfgs.size(); ++k) {
    cfgs[k].run.seed = first_seed_ + static_cast<unsigned>(k);
    if (!read_packing(cfgs[k], specimens_[k])) todo.push_back(k);
  }
  const std::size_t read = specimens_.size() - todo.size();
  if (verbose && read > 0)
    std::printf("triaxdem: %zu of %d specimens of %ld balls read from the packing store %s\n", read, count,
                cfg_.particles.count, cfg_.packing_store.c_str());
  if (todo.empty()) return;
  const bool one_by_one = (batch_ <= 1 || todo.size() <= 1) && (workers_ <= 1 || todo.size() <= 1);
  std::optional<Progress> progress;
  if (verbose && todo.size() > 1) {
    const int at_once = one_by_one ? 1 : std::min(static_cast<int>(todo.size()), batch_ > 1 ? batch_ : workers_);
    progress.emplace("triaxdem: packing " + std::to_string(todo.size()) + " specimens of " +
                         std::to_string(cfg_.particles.count) + " balls, " + std::to_string(at_once) + " at once",
                     static_cast<long>(todo.size()));
    progress->update(0, "specimens");
  }
  long packed = 0;
  auto made = [&](std::size_t k) {
    PackedCell& s = specimens_[k];
    s.void_ratio = void_ratio_of(s.balls, s.cell);
    write_packing(cfgs[k], s);
    if (progress) progress->update(++packed, "specimens");
  };
  if (batch_ > 1 && todo.size() > 1) {
    for (std::size_t first = 0; first < todo.size(); first += static_cast<std::size_t>(batch_)) {
      const std::size_t last = std::min(todo.size(), first + static_cast<std::size_t>(batch_));
      std::vector<Config> chunk;
      for (std::size_t j = first; j < last; ++j) chunk.push_back(cfgs[todo[j]]);
      const std::vector<PreparedCell> prepared = prepare_periodic_specimens(chunk);
      for (std::size_t j = first; j < last; ++j) {
        specimens_[todo[j]].balls = prepared[j - first].balls;
        specimens_[todo[j]].cell = prepared[j - first].cell;
        made(todo[j]);
      }
    }
  } else if (one_by_one) {
    for (const std::size_t k : todo) {
      prepare_periodic_specimen(cfgs[k], specimens_[k].balls, specimens_[k].cell, verbose && k == todo.front());
      made(k);
    }
  } else {  // each specimen in a child, sent back as packed_bytes
    forked_runs(
        todo.size(), workers_,
        [&](std::size_t j, int fd) {
          PackedCell& s = specimens_[todo[j]];
          prepare_periodic_specimen(cfgs[todo[j]], s.balls, s.cell, false);
          s.void_ratio = void_ratio_of(s.balls, s.cell);
          const std::string bytes = packed_bytes(s);
          put_bytes(fd, bytes.data(), bytes.size());
        },
        [&](std::size_t j, int fd) {
          if (!get_packed(fd, specimens_[todo[j]], static_cast<std::size_t>(cfg_.particles.count))) return false;
          made(todo[j]);
          return true;
        },
        "specimen preparation");
  }
  if (progress) progress->finish("");
}

StateMatch PeriodicLab::grow_cell(int factor, const StateMatch& state) {
  if (factor < 1) throw std::invalid_argument("cell factor " + std::to_string(factor) + " (allowed: 1 or more)");
  cfg_ = larger_cell(cfg_, factor);
  cell_factor_ *= factor;
  // The friction that packs the data's void ratio in a small cell packs a larger one to another.
  StateMatch grown = state;
  if (verbose_)
    std::printf("triaxdem: the cell grows to %ld balls (%d x the config's): its specimens are packed again%s\n",
                cfg_.particles.count, cell_factor_, state.tests > 0 ? ", to the data's void ratio" : "");
  if (state.tests > 0) {
    MatchPlan plan;
    plan.first_seed = first_seed_;
    plan.specimens = state.specimens;
    plan.workers = workers_;
    // A walled cell matched on its interior stays so while it is still smaller than the data's specimen.
    if (!larger_specimen(state.data_balls, static_cast<Real>(cfg_.particles.count)))
      grown.data_balls = std::numeric_limits<Real>::quiet_NaN();
    plan.data_balls = grown.data_balls;
    cfg_.periodic.prep_mu_s = grown.prep_mu_s = prep_friction_for(cfg_, state.target, grown.reached, verbose_, plan);
  }
  pack(specimens(), verbose_);
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
  return run_part(m, like, M, 0, like.size() * M);
}

Ensemble PeriodicLab::run_part(const Model& m, const std::vector<TriaxialTest>& like, std::size_t members,
                               std::size_t from, std::size_t to) {
  const std::size_t T = like.size();
  if (members > specimens_.size() || from > to || to > T * members)
    throw std::logic_error("periodic lab: cases beyond its specimens");
  std::vector<Case> cases;
  for (std::size_t c = from; c < to; ++c)
    cases.push_back({like[c % T].material, like[c % T].sigma3, static_cast<int>(c / T)});
  const std::vector<TriaxialTest> done = run_cases(m, cases);
  Ensemble out(T);
  for (std::size_t j = 0; j < done.size(); ++j) out[(from + j) % T].push_back(done[j]);
  return out;
}

std::vector<TriaxialTest> PeriodicLab::run_each(const Model& m, const std::vector<TriaxialTest>& like) {
  std::vector<Case> cases;
  for (std::size_t j = 0; j < like.size(); ++j)
    cases.push_back({like[j].material, like[j].sigma3, static_cast<int>(j % static_cast<std::size_t>(members_))});
  return run_cases(m, cases);
}

}  // namespace dem
