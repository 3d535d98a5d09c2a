#pragma once
/// How the step's parts are timed (Simulation::step) and read back per stage (run_stage).

namespace dem {

/// One step in this many has its parts timed, each behind a fence, and counts for as many: on a GPU a fence holds
/// the host until the device is done, and the other steps go through without one. The parts' times are estimates
/// (a stage of thousands of steps samples hundreds of them); the stage's wall time (stage_loop.hpp) is measured.
constexpr long kTimedEvery = 16;

/// Sampled steps among the steps numbered [0, s) (those whose number is a multiple of kTimedEvery).
constexpr long sampled_steps_before(long s) { return s <= 0 ? 0 : (s - 1) / kTimedEvery + 1; }

/// A stage's first kTimedFirst steps are each timed and count once (run_stage): a stage too short for hundreds of
/// samples is then measured, not estimated. On a busy machine one sampled step that the scheduler stalled counted 16
/// times, and a walled shear of 69 steps read -648 ns a particle-step of host work. On a GPU their fences, five a step
/// of some microseconds each, add about 10 ms to a stage (reasoned, not measured).
constexpr long kTimedFirst = 256;

/// What the timed steps of a stage of the steps numbered [first, end) count for together: each of its first
/// kTimedFirst once, and after them each multiple of kTimedEvery kTimedEvery times.
constexpr long timed_weight(long first, long end) {
  if (end <= first) return 0;
  const long each_end = end < first + kTimedFirst ? end : first + kTimedFirst;
  return (each_end - first) + kTimedEvery * (sampled_steps_before(end) - sampled_steps_before(each_end));
}

}  // namespace dem
