#pragma once
/// How the step's parts are timed (Simulation::step) and read back per stage (run_stage).

namespace dem {

/// One step in this many has its parts timed, each behind a fence, and counts for as many: on a GPU a fence holds
/// the host until the device is done, and the other steps go through without one. The parts' times are estimates
/// (a stage of thousands of steps samples hundreds of them); the stage's wall time (stage_loop.hpp) is measured.
constexpr long kTimedEvery = 16;

/// Sampled steps among the steps numbered [0, s) (those whose number is a multiple of kTimedEvery).
constexpr long sampled_steps_before(long s) { return s <= 0 ? 0 : (s - 1) / kTimedEvery + 1; }

}  // namespace dem
