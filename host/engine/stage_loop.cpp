#include "host/engine/stage_loop.hpp"
#include "host/engine/part_sampling.hpp"

#include "host/util/progress.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>

namespace dem {

namespace {

StageEnd run_steps(Simulation& sim, const StageSteps& stage, CheckpointPlan* plan) {
  long n = stage.first;
  StageTiming t;  // the host's parts; run_stage fills in the rest
  const auto ended = [&t](long last, bool done) { return StageEnd{last, done, t}; };
  try {
    for (; n <= stage.last; ++n) {
      StepPlan next;
      {
        const SyncScope part(SyncPart::kControl);
        const WallClock clock(t.control);
        next = stage.before(n);
      }
      if (next.done) return ended(n - 1, true);
      {
        const SyncScope part(SyncPart::kStep);
        sim.step(next.measure);
      }
      const SyncScope part(SyncPart::kRecord);
      bool done = false;
      {
        const WallClock clock(t.after);
        done = stage.after && stage.after(n, next.measure);
      }
      if (done) return ended(n, true);  // the last step's work after it counted
      if (!plan || !stage.checkpoint) continue;
      if (plan->due(sim.step_count())) {
        const WallClock clock(t.checkpoints);
        stage.checkpoint(n);
        plan->clock.written();
      }
      if (plan->stop(sim.step_count())) throw run_stopped(*plan, sim.step_count());
    }
  } catch (const BlowUp&) {
    if (stage.save_blowup) stage.save_blowup();
    throw;
  }
  return ended(n - 1, false);
}

/// Nanoseconds per particle-step of each part of a stage, in the columns' order: rebuild, ball-ball, ball-wall,
/// membrane, gather + integration, boundaries, the host's work between steps, and of it the stage's control, its
/// work after a step and its checkpoints.
std::array<double, 10> ns_per_part(const StageTiming& t) {
  const double work = static_cast<double>(t.balls) * static_cast<double>(t.steps);
  const StageTimes& p = t.parts;
  std::array<double, 10> ns{p.rebuild,  p.forces,  p.walls,   p.membrane,    p.integrate,
                            p.boundaries, t.host(), t.control, t.after, t.checkpoints};
  for (double& x : ns) x = work > 0 ? 1e9 * x / work : 0;
  return ns;
}

}  // namespace

void fit_sampled_parts(StageTiming& timing) {
  StageTimes& t = timing.parts;
  const double room = timing.wall - timing.control - timing.after - timing.checkpoints - t.rebuild;
  const double sampled = t.forces + t.integrate + t.boundaries + t.membrane + t.walls;
  if (sampled <= room || sampled <= 0) return;
  for (double* x : {&t.forces, &t.integrate, &t.boundaries, &t.membrane, &t.walls}) *x *= std::max(0.0, room) / sampled;
}

StageEnd run_stage(Simulation& sim, const StageSteps& stage, CheckpointPlan* plan) {
  const auto t0 = std::chrono::steady_clock::now();
  const StageTimes parts0 = sim.times();
  const long step0 = sim.step_count();
  const SyncTally syncs0 = sync_tally();
  sim.time_each_step_until(step0 + kTimedFirst);
  StageEnd end = run_steps(sim, stage, plan);
  const SyncTally syncs1 = sync_tally();
  for (int k = 0; k < kSyncParts; ++k) end.timing.syncs[static_cast<std::size_t>(k)] = syncs1[k] - syncs0[k];
  end.timing.balls = sim.particles().n;
  end.timing.steps = sim.step_count() - step0;
  end.timing.wall = seconds_since(t0);
  // The timed steps' weights (part_sampling.hpp) scaled to the steps the stage ran, so that a stage whose length is
  // no multiple of kTimedEvery does not count its samples for steps it did not run.
  const long weight = timed_weight(step0, sim.step_count());
  const double f = weight > 0 ? static_cast<double>(end.timing.steps) / static_cast<double>(weight) : 0;
  StageTimes& t = end.timing.parts;
  t = sim.times().since(parts0);
  for (double* x : {&t.forces, &t.integrate, &t.boundaries, &t.membrane, &t.walls}) *x *= f;  // the rebuild: every time
  fit_sampled_parts(end.timing);
  const double n = std::max(1, sim.particles().n);
  end.timing.ball_pairs = sim.ball_contacts().n / n;
  end.timing.wall_pairs = sim.wall_contacts().n / n;
  return end;
}

std::string timings_csv(const std::vector<StageTiming>& stages) {
  std::string s = "stage,balls,steps,wall_s,particle_steps_per_s,rebuilds,rebuild_ns,ball_ball_ns,ball_wall_ns,"
                  "membrane_ns,gather_integrate_ns,boundaries_ns,host_ns,ball_pairs_per_ball,wall_pairs_per_ball,"
                  "launches_per_step,syncs_per_step,allocations_per_step,syncs_per_rebuild,record_syncs_per_step,"
                  "host_control_ns,host_after_ns,host_checkpoint_ns\n";
  char line[512];
  for (const StageTiming& t : stages) {
    const auto ns = ns_per_part(t);
    const double steps = std::max(1L, t.steps), rebuilds = std::max(1L, t.parts.rebuilds);
    const SyncCounts each = t.per_step_part();
    std::snprintf(line, sizeof line,
                  "%s,%ld,%ld,%.3f,%.4g,%ld,%.2f,%.2f,%.2f,%.2f,%.2f,%.2f,%.2f,%.3f,%.3f,%.3f,%.3f,%.3f,%.2f,%.3f,"
                  "%.2f,%.2f,%.2f\n",
                  t.name.c_str(), t.balls, t.steps, t.wall, t.rate(), t.parts.rebuilds, ns[0], ns[1], ns[2], ns[3],
                  ns[4], ns[5], ns[6], t.ball_pairs, t.wall_pairs, each.launches / steps, each.syncs() / steps,
                  each.allocations / steps, t.syncs[static_cast<int>(SyncPart::kRebuild)].syncs() / rebuilds,
                  t.syncs[static_cast<int>(SyncPart::kRecord)].syncs() / steps, ns[7], ns[8], ns[9]);
    s += line;
  }
  return s;
}

std::string timings_table(const std::vector<StageTiming>& stages) {
  std::string s = "                                                     | ns per particle-step\n"
                  "stage                  balls    steps  wall s psteps/s | rebuild ball-ball ball-wall membrane "
                  "integrate boundaries    host\n";
  char line[400];
  for (const StageTiming& t : stages) {
    const auto ns = ns_per_part(t);
    std::snprintf(line, sizeof line, "%-20s %7ld %8ld %7.1f %8.3g | %7.1f %9.1f %9.1f %8.1f %9.1f %10.1f %7.1f\n",
                  t.name.c_str(), t.balls, t.steps, t.wall, t.rate(), ns[0], ns[1], ns[2], ns[3], ns[4], ns[5], ns[6]);
    s += line;
  }
  return s;
}

}  // namespace dem
