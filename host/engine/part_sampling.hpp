#pragma once
/// How the step's parts are timed (Simulation::step) and read back per stage (run_stage).

namespace dem {

/// One step in this many has its parts timed, each behind a fence, and counts for as many: on a GPU a fence holds
/// the host until the device is done, and the other steps go through without one. The parts' times are estimates
/// (a stage of thousands of steps samples hundreds of them); the stage's wall time (stage_loop.hpp) is measured.
constexpr long kTimedEvery = 16;

/// A stage's first kTimedFirst steps are each timed and count once (run_stage): a stage too short for hundreds of
/// samples is then measured, not estimated. On a busy machine one sampled step that the scheduler stalled counted 16
/// times, and a walled shear of 69 steps read -648 ns a particle-step of host work. On a GPU their fences, five a step
/// of some microseconds each, add about 10 ms to a stage (reasoned, not measured).
constexpr long kTimedFirst = 256;

/// What step number `step` counts for in its stage's part times (Simulation::step) when the steps before
/// `each_until` are each timed: 1 for those, kTimedEvery for a later multiple of kTimedEvery, 0 for the rest.
constexpr long step_weight(long step, long each_until) {
  return step < each_until ? 1 : step % kTimedEvery == 0 ? kTimedEvery : 0;
}

/// What the timed steps of a stage of the steps numbered [first, end) count for together (run_stage): the sum of
/// their step weights, the first kTimedFirst each timed. A loop over the stage's steps, once a stage: the rule stays
/// in step_weight alone.
constexpr long timed_weight(long first, long end) {
  long weight = 0;
  for (long s = first; s < end; ++s) weight += step_weight(s, first + kTimedFirst);
  return weight;
}

}  // namespace dem
