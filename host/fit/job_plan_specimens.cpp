/// The plan's packings (host/fit/job_planner.hpp): the state matches, the scatter and prediction specimens, and the
/// cell's bias check, each less what the packing store holds.
#include <algorithm>
#include <cmath>

#include "host/fit/cell_bias.hpp"
#include "host/fit/job_planner.hpp"
#include "host/lab/periodic_lab.hpp"
#include "host/lab/state_match.hpp"
#include "host/util/text_format.hpp"

namespace dem::job_planning {

namespace {

/// How many of the specimens of seeds first .. first + count - 1 of `cell` the packing store holds.
int stored_specimens(Config cell, unsigned first, int count) {
  int n = 0;
  PackedCell s;
  for (int k = 0; k < count; ++k) {
    cell.run.seed = first + static_cast<unsigned>(k);
    n += read_packing(cell, s) ? 1 : 0;
  }
  return n;
}

/// A match's packings at the ends of [0, 1] (preparation_reach), in packings of a typical friction: the
/// frictionless end's settling takes 2.3 to 3.6 times as many steps.
PackingCost match_ends() {
  const PackingCost none = packing_cost_at(0), full = packing_cost_at(1);
  return {none.low + full.low, none.high + full.high};
}

}  // namespace

bool stored_match(const Config& base, const std::vector<TriaxialTest>& tests, MatchPlan plan, Config& matched) {
  plan.stored_only = true;
  plan.store.clear();
  try {
    StateMatch m;
    matched = matched_state(base, tests, m, false, plan);
    return true;
  } catch (const NotPacked&) {
    return false;
  }
}

void Planner::match_packings_stage(const std::string& name) {
  const PackingCost ends = match_ends();
  const double halvings = match_packings - 2;
  add.packings(name, "the data's void_ratio", lab, (halvings + ends.low) * kStateMatchSpecimens,
               (halvings + ends.high) * kStateMatchSpecimens, kStateMatchSpecimens,
               "up to " + std::to_string(match_packings) + " packings of " + std::to_string(kStateMatchSpecimens) +
                   " specimens");
  note_ends();
}

void Planner::note_ends() {
  const std::string note = "a state match packs at preparation friction 0, where the balls slide on and settle in " +
                           fmt("%.1f", packing_cost_at(0).low) + " to " + fmt("%.1f", packing_cost_at(0).high) +
                           " times a packing's steps: counted so";
  if (std::find(plan.notes.begin(), plan.notes.end(), note) == plan.notes.end()) plan.notes.push_back(note);
}

void Planner::specimens() {
  if (match_stored && void_ratio)
    plan.notes.push_back("state match: its packings are in the packing store (preparation friction " +
                         fmt("%.4g", lab_cell.periodic.prep_mu_s) + ")");
  if (void_ratio && !match_stored) match_packings_stage("state match");
  // The match's last packing is the first specimens'; with the match known, the store says which are left.
  const int to_pack = match_stored ? S - stored_specimens(lab_cell, seed, S) : S - shared;
  add.packings("scatter specimens", "[calibrate] scatter_specimens", lab, to_pack, to_pack, to_pack,
               std::to_string(to_pack) + " packings");
}

/// A material's cell's bias check: its own state match (the bracket's two ends around the lab's friction and its
/// two halvings where it holds the answer; else its ends, the whole range's and kCellCheckPrepSteps halvings, each
/// end at its friction's cost), its specimens and runs. None where the data's specimens have the cell's balls
/// (measure_cell_bias).
void Planner::bias_check(const std::string& material, const std::vector<TriaxialTest>& tests) {
  const int check_low = 4, check_high = 2 + 2 + kCellCheckPrepSteps;
  const bool checked = std::any_of(tests.begin(), tests.end(), [&](const TriaxialTest& t) {
    return cell_bias_extrapolation(static_cast<Real>(lab.balls), kCellCheckFactor, t.specimen_balls) != 0;
  });
  if (!checked) {
    plan.notes.push_back(material + ": the data's specimens have the cell's " + n + " balls: no cell's bias check");
    return;
  }
  // The check's own match (measure_cell_bias' plan), replayed on the store where the lab's match is known.
  MatchPlan check_plan;
  check_plan.first_seed = seed + kCellCheckSeedOffset;
  check_plan.steps = kCellCheckPrepSteps;
  check_plan.workers = in.at_once;
  check_plan.around = std::sqrt(lab_cell.periodic.prep_mu_s);
  Config check_cell = larger_cell(lab_cell, kCellCheckFactor);
  const bool check_stored =
      match_stored && stored_match(larger_cell(lab_cell, kCellCheckFactor), tests, check_plan, check_cell);
  const int check_to_pack =
      check_stored ? kCellCheckSpecimens - stored_specimens(check_cell, check_plan.first_seed, kCellCheckSpecimens)
                   : kCellCheckSpecimens - shared;
  const std::string setting = "[particles] count (the bias check runs cells of " + std::to_string(kCellCheckFactor) +
                              " times it where the data's specimen_balls exceed the cell's)";
  const auto [root_lo, root_hi] = match_bracket(check_plan.around);
  const PackingCost lo = packing_cost_at(root_lo * root_lo), hi = packing_cost_at(root_hi * root_hi),
                    ends = match_ends();
  if (void_ratio && !check_stored) {
    add.packings(material + ": cell's bias check, state match", setting, check,
                 (lo.low + hi.low + 2) * kStateMatchSpecimens,
                 (lo.high + hi.high + ends.high + kCellCheckPrepSteps) * kStateMatchSpecimens, kStateMatchSpecimens,
                 std::to_string(check_low) + " to " + std::to_string(check_high) + " packings of " +
                     std::to_string(kStateMatchSpecimens) + " specimens");
    note_ends();
  }
  add.packings(material + ": cell's bias check, specimens", setting, check, check_to_pack, check_to_pack,
               kCellCheckSpecimens, std::to_string(check_to_pack) + " packings");
  add.runs(material + ": cell's bias check, runs", setting, check, tests, 1, kCellCheckSpecimens, kCellCheckSpecimens,
           std::to_string(kCellCheckSpecimens * static_cast<int>(tests.size())) + " runs of " +
               std::to_string(check.balls) + " balls");
}

void Planner::walls_specimens() {
  const int P = static_cast<int>(cc.predict_specimens);
  if (void_ratio) match_packings_stage("prediction (walls): state match");
  add.packings("prediction (walls): specimens", "[calibrate] predict_specimens", lab, P - shared, P - shared, P,
               std::to_string(std::max(0, P - shared)) + " packings");
}

}  // namespace dem::job_planning
