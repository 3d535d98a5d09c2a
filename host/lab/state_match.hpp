#pragma once
/// The measured specimens' state matched: the preparation friction with which the simulator's specimens pack to the
/// data's void ratio (host/lab/state_match.cpp), for the lab's cell, a grown cell or the cell-bias check's cells.
#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "host/config/config.hpp"
#include "host/data/measured.hpp"

namespace dem {

/// Specimens whose mean void ratio the preparation friction is matched on. One specimen of 120 balls scatters by
/// about 0.011 in void ratio at one friction (perf/specimen_scatter.sh), and a void ratio 0.001 lower adds about
/// 0.01-0.02 to q/sigma3 (docs/history/calibration.md): a match on one specimen leaves that scatter as an offset of
/// every specimen packed with its friction. The mean of two, packed side by side with 2 workers, costs no more time.
constexpr int kStateMatchSpecimens = 2;

/// How the preparation friction is looked for: `steps` halvings, each packing the specimens of packing seeds
/// first_seed, first_seed + 1, ... (`specimens` of them, up to `workers` at once: the answer is the same for any
/// number of workers).
struct MatchPlan {
  unsigned first_seed = 0;
  int specimens = kStateMatchSpecimens;
  int steps = 8;
  int workers = 1;
  int cell_factor = 1;  ///< the specimens are packed in cells of this many times the base config's balls
  /// Where the answer is expected (sqrt(prep_mu_s), from a smaller cell's match; negative: nowhere): the halvings
  /// start from the bracket of +-kMatchBracket around it, and from [0, 1] only where the target lies outside.
  Real around = -1;
  /// A run store (PeriodicLab::set_run_store) that keeps each packing's mean void ratio; "" keeps nothing.
  std::string store;
  /// Where finite, the specimens are walled cells matched as specimens of this many balls would be, on their
  /// interior (void_ratio_at_size; matched_state sets it, StateMatch::data_balls says it); NaN: on the whole cell.
  Real data_balls = std::numeric_limits<Real>::quiet_NaN();
  /// Packs nothing: reads the packings from the packing store (Config::packing_store) and throws NotPacked at one it
  /// lacks. A job's plan replays its matches so, to count only the packings still to make.
  bool stored_only = false;
};

/// A MatchPlan::stored_only match met a packing the packing store does not hold.
struct NotPacked : std::runtime_error {
  using std::runtime_error::runtime_error;
};
/// Half the width of a MatchPlan's bracket in sqrt(prep_mu_s): a cell of four times the balls packs within about
/// 0.005 in void ratio of the smaller one at one friction, 0.02-0.05 in sqrt(prep_mu_s) on the shipped configs.
/// Its two ends and two halvings reach the 1/32 of five halvings of [0, 1] with four packings instead of seven.
constexpr Real kMatchBracket = 1.0 / 16;
/// The bracket's ends in sqrt(prep_mu_s) around `around`, within [0, 1].
inline std::pair<Real, Real> match_bracket(Real around) {
  return {std::max(Real(0), around - kMatchBracket), std::min(Real(1), around + kMatchBracket)};
}
/// The plan for a lab's specimens: its first seeds ([run] seed on), in the cell it runs ([calibrate] cell_factor,
/// the config's own where "auto"), 8 halvings, `workers` at once.
MatchPlan match_plan(const Config& base, int workers);

/// How far (in void ratio) a data state may lie outside what a cell's preparation reaches and still be matched
/// by the nearest end. Table 6's glass beads (e 0.60-0.61) lie 0.01-0.02 from the densest packing of the shipped
/// cells (0.589 for 120 balls), which the nearest end serves; a gap of a tenth is as large as the whole range the
/// preparation friction spans (0.59-0.87), another state, and is refused.
constexpr Real kMaxStateGap = 0.05;

/// The mean void ratios the plan's specimens of the base config pack to after their preparation with friction 0
/// (the densest) and 1 (the loosest): the states a calibration can match.
std::pair<Real, Real> preparation_reach(const Config& base, const MatchPlan& plan);

/// The preparation friction ([periodic] prep_mu_s) with which the plan's specimens of the base config pack to a
/// mean void ratio of `target` after their preparation: bisection on sqrt(prep_mu_s) over [0, 1] (more friction,
/// a looser packing; the root spreads the steps where the void ratio changes fastest). `reached` receives their
/// mean void ratio at the answer; a target beyond what [0, 1] reaches gets the nearest end, and one more than
/// kMaxStateGap beyond it throws DataError. 8 halvings take sqrt(prep_mu_s) to 1/256 of its range; a plan's
/// bracket (MatchPlan::around) needs fewer to reach the same resolution.
Real prep_friction_for(const Config& base, Real target, Real& reached, bool verbose, const MatchPlan& plan);

/// The measured specimens' state and the preparation that packs it (matched_state).
struct StateMatch {
  int tests = 0;                                            ///< tests that give a void ratio
  Real target = std::numeric_limits<Real>::quiet_NaN();     ///< their mean void ratio
  Real reached = std::numeric_limits<Real>::quiet_NaN();    ///< the matched specimens' mean after preparation
  int specimens = 0;                                        ///< how many were matched
  Real prep_mu_s = std::numeric_limits<Real>::quiet_NaN();
  /// The data's specimen's balls where a walled cell of fewer was matched on its interior (MatchPlan::data_balls):
  /// `target` is then the data's void ratio and `reached` the cell's specimens' at the data's size; NaN: whole cells.
  Real data_balls = std::numeric_limits<Real>::quiet_NaN();
};

/// The base config with the preparation friction that packs the mean void ratio of the tests that give one
/// (prep_friction_for); the base config itself when none does. A walled cell of fewer balls than the tests'
/// specimens (their mean specimen_balls) is matched on its interior (MatchPlan::data_balls) where [calibrate]
/// walled_match is "interior"; matched whole (the default), its walls' looser layer, a larger share of it, packs its
/// interior denser than the data's.
Config matched_state(const Config& base, const std::vector<TriaxialTest>& tests, StateMatch& m, bool verbose,
                     const MatchPlan& plan);

}  // namespace dem
