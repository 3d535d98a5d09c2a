/// run_periodic_batch: the periodic test's stages (periodic_stages.hpp) stepped for many specimens in one CellBatch.
#include <chrono>
#include <memory>
#include <stdexcept>

#include "host/engine/cell_batch.hpp"
#include "host/triax/periodic_stages.hpp"

namespace dem {

namespace {

using Clock = std::chrono::steady_clock;

/// One specimen's program in the batch: consolidation, then (unless consolidate_only) shear, each stage's steps
/// numbered from 1 as run_stage numbers them.
class Program {
 public:
  Program(CellBatch& batch, int s, BatchedTest& out, const GrainScales& g, bool consolidate_only, Clock::time_point t0)
      : batch_(batch), s_(s), out_(out), g_(g), consolidate_only_(consolidate_only), t0_(t0),
        cell_(cell_of(batch, s)), consolidation_(*cell_, out.result.params), stage_(consolidation_.steps()) {}

  /// Before the batch's step: whether the specimen steps in it, and `measure` its stage's wish. A stage that is
  /// done before its step ends here, and the next one plans the step.
  bool before(char& measure) {
    if (!batch_.running(s_)) return false;
    StepPlan plan;
    {
      const WallClock clock(host_.control);
      plan = stage_.before(n_);
    }
    while (plan.done && batch_.running(s_)) {
      end_stage({n_ - 1, true, host_});
      const WallClock clock(host_.control);
      if (batch_.running(s_)) plan = stage_.before(n_);
    }
    measure = plan.measure;
    return batch_.running(s_);
  }

  /// After a batch step the specimen took part in.
  void after(bool measured) {
    if (!batch_.running(s_)) {
      out_.blowup = batch_.blowup(s_);
      return;
    }
    bool done = false;
    {
      const WallClock clock(host_.after);
      done = stage_.after(n_, measured);
    }
    if (done) end_stage({n_, true, host_});
    else if (++n_ > stage_.last) end_stage({n_ - 1, false, host_});
  }

 private:
  CellBatch& batch_;
  int s_;
  BatchedTest& out_;
  GrainScales g_;
  bool consolidate_only_;
  Clock::time_point t0_;
  std::unique_ptr<CellControl> cell_;
  Consolidation consolidation_;
  std::unique_ptr<Shear> shear_;
  StageSteps stage_;
  long n_ = 1;
  long first_step_ = 0;  ///< the specimen's step count at the stage's start
  StageTiming host_;     ///< the stage's host work so far (control, after), as run_stage splits it

  /// The stage ended (run_stage's StageEnd): on to the next stage, or stopped.
  void end_stage(StageEnd e) {
    host_ = StageTiming();
    e.timing.balls = batch_.balls(s_);
    e.timing.steps = batch_.step_count(s_) - first_step_;
    first_step_ = batch_.step_count(s_);
    if (shear_) {
      shear_->end(e.timing, std::chrono::duration<double>(Clock::now() - t0_).count());
      batch_.stop(s_);
      return;
    }
    out_.failure = consolidation_.end(e);
    out_.consolidation = e;
    out_.result.consolidation_steps = e.step;
    out_.result.stages.push_back(e.timing);
    if (!out_.failure.empty() || consolidate_only_) {
      if (out_.failure.empty()) {
        out_.balls = batch_.balls_of(s_);
        out_.domain = batch_.domain(s_);
      }
      batch_.stop(s_);
      return;
    }
    shear_ = std::make_unique<Shear>(*cell_, out_.result, g_, nullptr, nullptr);
    stage_ = shear_->steps();
    n_ = 1;
  }
};

}  // namespace

std::vector<BatchedTest> run_periodic_batch(const std::vector<Simulation*>& sims,
                                            const std::vector<PeriodicTriaxialParams>& prms, bool consolidate_only,
                                            std::array<long, 2>* steps) {
  const auto t0 = Clock::now();
  const std::size_t S = sims.size();
  if (prms.size() != S) throw std::invalid_argument("run_periodic_batch: a parameter set per specimen");
  std::vector<BatchedTest> out(S);
  std::vector<GrainScales> g(S);
  for (std::size_t s = 0; s < S; ++s) out[s].result = start_result(*sims[s], prms[s], g[s]);
  CellBatch batch(std::vector<const Simulation*>(sims.begin(), sims.end()));
  std::vector<std::unique_ptr<Program>> programs;
  for (std::size_t s = 0; s < S; ++s)
    programs.push_back(std::make_unique<Program>(batch, static_cast<int>(s), out[s], g[s], consolidate_only, t0));
  std::vector<char> measure(S, 0), stepping(S, 0);
  while (batch.running_count() > 0) {
    for (std::size_t s = 0; s < S; ++s) stepping[s] = programs[s]->before(measure[s]);
    if (batch.running_count() == 0) break;
    batch.step(measure);
    for (std::size_t s = 0; s < S; ++s)
      if (stepping[s]) programs[s]->after(measure[s] != 0);
  }
  if (steps) *steps = {batch.steps(), batch.rebuild_steps()};
  return out;
}

}  // namespace dem
