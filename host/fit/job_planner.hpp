#pragma once
/// The builder behind plan_job (host/fit/job_plan.hpp), shared by its files: job_plan.cpp (the stages' arithmetic, a
/// material's stages in the order the job runs them, the notes), job_plan_specimens.cpp (what is packed: the state
/// matches, the scatter and prediction specimens, the cell's bias check) and job_plan_tests.cpp (the runs beyond the
/// search: a diagnosis's extensions, compression tests, membrane tests).
#include <string>
#include <vector>

#include "host/fit/job_plan.hpp"
#include "host/lab/run_cost.hpp"
#include "host/lab/state_match.hpp"

namespace dem::job_planning {

/// Mean of a cost over the tests' pressures.
template <class F>
double mean_over(const std::vector<TriaxialTest>& tests, F f) {
  double s = 0;
  for (const TriaxialTest& t : tests) s += f(t.sigma3);
  return tests.empty() ? 0 : s / static_cast<double>(tests.size());
}

/// Replays a state match on the packing store's packings alone (MatchPlan::stored_only): true, with `matched` its
/// config, where the store holds every packing it needs.
bool stored_match(const Config& base, const std::vector<TriaxialTest>& tests, MatchPlan plan, Config& matched);

/// The builder of a plan's stages.
struct Stages {
  JobPlan& plan;
  int at_once;
  /// `n` packings of `cost`'s cell, up to `side` of them at once, `low_n` at the lower end.
  void packings(const std::string& name, const std::string& setting, const CellCost& c, double low_n, double n,
                int side, const std::string& what);
  /// Runs of `tests` on `low_k` to `k` specimens per point, `points` points one after another.
  void runs(const std::string& name, const std::string& setting, const CellCost& c,
            const std::vector<TriaxialTest>& tests, double points, int low_k, int k, const std::string& what);
};

/// What every stage of a plan reads: the job, the lab's cell and the check's, the specimens and the state match.
struct Planner {
  const PlanInput& in;
  JobPlan plan;
  Stages add{plan, in.at_once};
  const CalibrateConfig& cc = in.cell.calibrate;
  int factor = 1;
  Config cell;              ///< the lab's cell as the job grows it, with a preparation friction where matched
  bool void_ratio = false;  ///< the data give void ratios: the specimens are matched to them
  CellCost lab, check;
  /// The lab's cost at the searched points: where mu_s is free, at its range's centre, not the base's friction (a
  /// frictionless base's own runs settle their packings again, the searched ones need not).
  CellCost searched;
  int S = 0, K = 0, K_low = 0;  ///< scatter specimens, ensemble (auto: 1 to S)
  bool auto_ensemble = false;
  std::string n;  ///< the lab's balls
  int match_packings = 0;
  bool match_stored = false;  ///< the packing store holds the state match's packings
  Config lab_cell;            ///< the matched cell (as the store knows it)
  unsigned seed = 0;
  int shared = 0;  ///< specimens the match's last packing gives the scatter

  explicit Planner(const PlanInput& input);

  // job_plan.cpp
  /// A material's stages: its scatter runs, the cell's bias check, the search, and what predicts.
  void material(const std::string& material, const std::vector<TriaxialTest>& tests);
  /// Whether the search runs one specimen a point ([calibrate] method; diagnose and two fidelities search with the
  /// ensemble).
  bool one_specimen() const { return cc.one_specimen() && !in.diagnose && !in.two_fidelity; }
  /// What the counts rest on: the speed measured, a run's and a packing's steps, and the choices made on the way.
  void notes();

  // job_plan_specimens.cpp
  /// The lab's own specimens: the state match and the scatter specimens.
  void specimens();
  /// A material's cell's bias check: its own state match, its specimens and runs.
  void bias_check(const std::string& material, const std::vector<TriaxialTest>& tests);
  /// The walled cell's own preparation to the data's state, once for all materials.
  void walls_specimens();
  /// The state match's packings, where the store does not hold them: `name`'s stage.
  void match_packings_stage(const std::string& name);
  /// Says once that a match's ends are counted at their own cost.
  void note_ends();

  // job_plan_tests.cpp
  /// A diagnosis's extension fits added to its stage.
  void extension_points(const std::vector<TriaxialTest>& tests);
  /// A material's membrane tests: two fidelities' rounds where the job fits them, then the prediction.
  void membrane(const std::string& material, const std::vector<TriaxialTest>& tests, long points,
                const std::string& search_what);
  /// A material's compression tests (--compression).
  void compressions(const std::string& material, long points);
};

}  // namespace dem::job_planning
