#include "host/fit/job_plan.hpp"

#include <algorithm>
#include <cmath>

#include "host/fit/calibrate.hpp"
#include "host/fit/cell_bias.hpp"
#include "host/fit/diagnose.hpp"
#include "host/fit/job_planner.hpp"
#include "host/lab/state_match.hpp"
#include "host/util/text_format.hpp"

namespace dem {
namespace job_planning {

void Stages::packings(const std::string& name, const std::string& setting, const CellCost& c, double low_n, double n,
                      int side, const std::string& what) {
  if (n <= 0 || c.packing_steps <= 0) return;
  const int k = std::min(at_once, side);
  plan.stages.push_back({name, what + " of " + std::to_string(c.balls) + " balls", setting,
                         n * static_cast<double>(c.packing_steps) * static_cast<double>(c.balls),
                         c.seconds_of(low_n, c.packing_seconds(), k), c.seconds_of(n, c.packing_seconds(), k)});
}

void Stages::runs(const std::string& name, const std::string& setting, const CellCost& c,
                  const std::vector<TriaxialTest>& tests, double points, int low_k, int k, const std::string& what) {
  const double each_low = mean_over(tests, [&](Real s) { return c.run_seconds(s, false); });
  const double each = mean_over(tests, [&](Real s) { return c.run_seconds(s); });
  const double steps = mean_over(tests, [&](Real s) { return static_cast<double>(c.run_steps(s)); });
  const double per_point_low = static_cast<double>(tests.size()) * low_k;
  const double per_point = static_cast<double>(tests.size()) * k;
  plan.stages.push_back({name, what, setting, points * per_point * steps * static_cast<double>(c.balls),
                         points * c.seconds_of(per_point_low, each_low, at_once),
                         points * c.seconds_of(per_point, each, at_once)});
}

Planner::Planner(const PlanInput& input) : in(input) {
  factor = static_cast<int>(std::max(cc.cell_factor, 1L));
  cell = larger_cell(in.cell, factor);
  for (const auto& m : in.materials)
    for (const TriaxialTest& t : m.second) void_ratio = void_ratio || std::isfinite(t.void_ratio);
  // A matched state is prepared with a friction of its own: the packing then has a preparation stage.
  if (void_ratio && cell.periodic.prep_mu_s < 0) cell.periodic.prep_mu_s = 0.5 * cell.ball.mu_s;
  lab = measure_cell_cost(cell);
  check = measure_cell_cost(larger_cell(cell, kCellCheckFactor));
  searched = lab;
  if (std::find(in.free.begin(), in.free.end(), "mu_s") != in.free.end())
    searched.mu_s = free_param("mu_s", model_of(in.cell)).value(0.5);
  S = static_cast<int>(cc.scatter_specimens);
  auto_ensemble = cc.ensemble == kAutoEnsemble;
  K = auto_ensemble ? S : static_cast<int>(cc.ensemble);
  K_low = auto_ensemble ? 1 : K;
  n = std::to_string(lab.balls);
  match_packings = 2 + MatchPlan{}.steps;
  // What the packing store holds already: the match replayed on its packings, then the specimens at its friction.
  Config matched = in.cell;
  match_stored = stored_match(in.cell, in.state_tests, match_plan(in.cell, in.at_once), matched);
  lab_cell = larger_cell(matched, factor);
  seed = in.cell.run.seed;
  shared = void_ratio ? kStateMatchSpecimens : 0;
}

void Planner::material(const std::string& material, const std::vector<TriaxialTest>& tests) {
  const std::string T = std::to_string(tests.size());
  add.runs(material + ": scatter runs", "[calibrate] scatter_specimens", lab, tests, 1, S, S,
           std::to_string(S * static_cast<int>(tests.size())) + " runs of " + n + " balls (" + std::to_string(S) +
               " specimens x " + T + " tests)");
  bias_check(material, tests);
  const long tried = in.diagnose ? static_cast<long>(extensions_of(model_of(in.cell)).size()) : 0;
  const bool one = one_specimen();
  const long points = (one ? planned_one_specimen_points(static_cast<int>(in.free.size()))
                           : planned_points(static_cast<int>(in.free.size()))) +
                      tried * 6;
  const std::string k = one ? "1" : auto_ensemble ? "1 to " + std::to_string(K) : std::to_string(K);
  const std::string search_what =
      std::to_string(points) + " points x " + T + " tests x " + k + " specimens of " + n + " balls" +
      (in.diagnose ? " (the base model, then " + std::to_string(tried) + " extensions)" : "");
  add.runs(material + (in.diagnose ? ": diagnosis" : ": search"),
           one             ? "[calibrate] method"
           : auto_ensemble ? "[calibrate] ensemble (auto)"
                           : "[calibrate] ensemble",
           searched, tests, static_cast<double>(points - tried * 6), one ? 1 : K_low, one ? 1 : K, search_what);
  if (in.diagnose) extension_points(tests);
  compressions(material, points);
  if (!in.diagnose && !in.two_fidelity)
    add.runs(material + ": scatter at the calibrated point", "[calibrate] scatter_specimens", searched, tests, 1, S, S,
             std::to_string(S * static_cast<int>(tests.size())) + " runs of " + n + " balls (" + std::to_string(S) +
                 " specimens x " + T + " tests)");
  if (std::find(in.reference_runs.begin(), in.reference_runs.end(), material) != in.reference_runs.end())
    add.runs(material + ": the reference point", "--reference", searched, tests, 1, K_low, K,
             "1 point x " + T + " tests x " + k + " specimens of " + n + " balls");
  if (in.membrane) {
    membrane(material, tests, points, search_what);
  } else if (in.walls) {
    const int P = static_cast<int>(cc.predict_specimens);
    add.runs(material + ": prediction (walls)", "[calibrate] predict_specimens", searched, tests, 1, P, P,
             std::to_string(P * static_cast<int>(tests.size())) + " runs of the walled cell of " + n + " balls");
  }
}

void Planner::notes() {
  const auto probed = [](const CellCost& c) {
    return c.probed_balls < c.balls ? " (probed on a lattice of " + std::to_string(c.probed_balls) + ")"
                                    : std::string();
  };
  plan.notes.push_back(
      fmt("speed measured here: %.0f ns a particle-step", lab.ns_per_particle_step) + " in the cell of " + n +
      " balls" + probed(lab) + ", " + fmt("%.0f", check.ns_per_particle_step) + " in the check's of " +
      std::to_string(check.balls) + probed(check) + "; " +
      (lab.batch > 1
           ? "runs in batches of up to " + std::to_string(lab.batch) +
                 fmt(", each cell adding %.3g of a run's time to its batch", lab.batch_growth)
           : std::to_string(in.at_once) + (in.at_once > 1 ? " runs at once, one thread each" : " run at a time")));
  plan.notes.push_back(fmt("a run of %.0f steps", static_cast<double>(lab.run_steps(cell.periodic.triax.sigma3))) +
                       fmt(" at %g kPa", 1e-3 * cell.periodic.triax.sigma3) +
                       fmt(" (%.0f s)", lab.run_seconds(cell.periodic.triax.sigma3)) +
                       fmt(", a packing of %.0f steps", static_cast<double>(lab.packing_steps)) +
                       fmt(" (%.0f s)", lab.packing_seconds()) + ": estimates (host/lab/run_cost.hpp)");
  if (lab.resettles())
    plan.notes.push_back(
        fmt("the base's sliding friction %g", static_cast<double>(lab.mu_s)) +
        " lets the balls slide on at sigma3: a run's consolidation settles its packing again, "
        "counted as " +
        fmt("%g", static_cast<double>(ResettleCost::low)) +
        fmt(" to %g packings' steps (measured 0.56 to 18.5: a frictionless packing is marginally rigid)",
            static_cast<double>(ResettleCost::high)));
  if (one_specimen())
    plan.notes.push_back("one specimen a point ([calibrate] method): the search runs its design and up to " +
                         std::to_string(OneSpecimenSearch{}.rounds) +
                         " rounds once each, on one specimen; the "
                         "scatter runs at the base and at the answer are its points there; an optimum on the edge "
                         "of a range searches again beyond it and runs more");
  else
    plan.notes.push_back(
        "a search counts its planned points on the whole ensemble: one whose optimum lies on the "
        "edge of a range searches again beyond it and runs more, and points far above the best run "
        "one specimen only (Table 6's S-1 once ran 636 runs where 264 were planned, now 200)");
  if (auto_ensemble && !one_specimen())
    plan.notes.push_back("ensemble \"auto\": the scatter runs choose 1 to " + std::to_string(S) +
                         " specimens a point (the fewest whose mean's standard error is half the data's noise): "
                         "the searches' times are that range");
  if (cc.cell_factor == kAutoCell && auto_ensemble && !one_specimen())
    plan.notes.push_back("cell \"auto\": where all " + std::to_string(S) +
                         " scatter specimens fall short, the "
                         "cell grows (up to " +
                         std::to_string(kMaxCellFactor) +
                         " x its balls) and every later "
                         "stage costs about that factor more: the job says so when it happens");
  plan.notes.push_back("packings in the packing store (" + in.cell.packing_store +
                       ") are read, not packed, and "
                       "not counted above");
}

}  // namespace job_planning

JobPlan plan_job(const PlanInput& in) {
  job_planning::Planner p(in);
  p.specimens();
  for (const auto& [material, tests] : in.materials) p.material(material, tests);
  if (in.walls) p.walls_specimens();
  p.notes();
  return p.plan;
}

}  // namespace dem
