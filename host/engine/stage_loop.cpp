#include "host/engine/stage_loop.hpp"

namespace dem {

StageEnd run_stage(Simulation& sim, const StageSteps& stage, CheckpointPlan* plan) {
  long n = stage.first;
  try {
    for (; n <= stage.last; ++n) {
      const StepPlan next = stage.before(n);
      if (next.done) return {n - 1, true};
      sim.step(next.measure);
      if (stage.after && stage.after(n, next.measure)) return {n, true};
      if (!plan || !stage.checkpoint) continue;
      if (plan->due(sim.step_count())) {
        stage.checkpoint(n);
        plan->clock.written();
      }
      if (plan->stop(sim.step_count())) throw run_stopped(*plan, sim.step_count());
    }
  } catch (const BlowUp&) {
    if (stage.save_blowup) stage.save_blowup();
    throw;
  }
  return {n - 1, false};
}

}  // namespace dem
