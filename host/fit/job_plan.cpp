#include "host/fit/job_plan.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include "host/fit/calibrate.hpp"
#include "host/fit/cell_bias.hpp"
#include "host/fit/diagnose.hpp"
#include "host/fit/two_fidelity.hpp"
#include "host/lab/periodic_lab.hpp"
#include "host/lab/run_cost.hpp"
#include "host/lab/state_match.hpp"
#include "host/triax/specimen.hpp"
#include "host/triax/triaxial.hpp"
#include "host/util/progress.hpp"
#include "host/util/text_format.hpp"

namespace dem {

/// A membrane specimen's build (layers compacted and settled) over one membrane test's steps: the README's small S-1
/// case builds its specimen in 3.5 minutes and runs the test in 2 min 45 s on 2 cores. A specimen is built once per
/// seed and cached (.specimens), then tested at every pressure.
constexpr Real kMembraneSpecimenOverTest = 1.3;

double JobPlan::low() const {
  double s = 0;
  for (const PlanStage& p : stages) s += p.low;
  return s;
}

double JobPlan::high() const {
  double s = 0;
  for (const PlanStage& p : stages) s += p.high;
  return s;
}

double JobPlan::particle_steps() const {
  double s = 0;
  for (const PlanStage& p : stages) s += p.particle_steps;
  return s;
}

const PlanStage& JobPlan::costliest() const {
  return *std::max_element(stages.begin(), stages.end(),
                           [](const PlanStage& a, const PlanStage& b) { return a.high < b.high; });
}

namespace {

std::string span(double low, double high) {
  return std::fabs(high - low) < 0.5 ? format_duration(high) : format_duration(low) + " to " + format_duration(high);
}

/// Wall seconds of `n` pieces of `each` seconds, `at_once` of them side by side.
double wall(double n, double each, int at_once) { return std::ceil(n / std::max(at_once, 1) - 1e-9) * each; }

/// Mean of a cost over the tests' pressures.
template <class F>
double mean_over(const std::vector<TriaxialTest>& tests, F f) {
  double s = 0;
  for (const TriaxialTest& t : tests) s += f(t.sigma3);
  return tests.empty() ? 0 : s / static_cast<double>(tests.size());
}

/// The builder of a plan's stages.
struct Stages {
  JobPlan& plan;
  int at_once;
  /// `n` packings of `cost`'s cell, up to `side` of them at once, `low_n` at the lower end.
  void packings(const std::string& name, const std::string& setting, const CellCost& c, double low_n, double n,
                int side, const std::string& what) {
    if (n <= 0 || c.packing_steps <= 0) return;
    const int k = std::min(at_once, side);
    plan.stages.push_back({name, what + " of " + std::to_string(c.balls) + " balls", setting,
                           n * static_cast<double>(c.packing_steps) * static_cast<double>(c.balls),
                           wall(low_n, c.packing_seconds(), k), wall(n, c.packing_seconds(), k)});
  }
  /// Runs of `tests` on `low_k` to `k` specimens per point, `points` points one after another.
  void runs(const std::string& name, const std::string& setting, const CellCost& c,
            const std::vector<TriaxialTest>& tests, double points, int low_k, int k, const std::string& what) {
    const double each = mean_over(tests, [&](Real s) { return c.run_seconds(s); });
    const double steps = mean_over(tests, [&](Real s) { return static_cast<double>(c.run_steps(s)); });
    const double per_point_low = static_cast<double>(tests.size()) * low_k, per_point = static_cast<double>(tests.size()) * k;
    plan.stages.push_back({name, what, setting, points * per_point * steps * static_cast<double>(c.balls),
                           points * wall(per_point_low, each, at_once), points * wall(per_point, each, at_once)});
  }
};

/// A stage repeated 1 to kFidelityRounds times: its time at the lower end once, its work and upper end every round.
void upto_rounds(PlanStage& p) {
  p.particle_steps *= kFidelityRounds;
  p.high *= kFidelityRounds;
}

/// Replays a state match on the packing store's packings alone (MatchPlan::stored_only): true, with `matched` its
/// config, where the store holds every packing it needs.
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

/// A membrane test's particle-step over a periodic cell's of the same balls: the membrane's facets, its nodes and the
/// platens. The small S-1 case at one thread (28 November): 83,450 steps of 3,662 balls in 1 min 48 s, 350 ns a
/// particle-step, against the cell probe's 150.
constexpr Real kMembraneStepOverCell = 2.3;

/// A membrane test's cost: its specimen's balls, the time step and speed of a cell of them, and its shear's steps as
/// the test plans them (shear_plan) at each pressure, a consolidation share more.
struct MembraneCost {
  Config cfg;
  CellCost cell;
  explicit MembraneCost(const Config& membrane) : cfg(membrane) {
    cfg.particles.count = specimen_ball_count(membrane);
    cell = measure_cell_cost(cfg);
  }
  double steps(Real sigma3) const {
    Config c = cfg;
    c.triaxial.sigma3 = sigma3;
    const ShearPlan p = shear_plan(c, cell.dt);
    return (1 + kConsolidationShare) * static_cast<double>(p.ramp + p.steps);
  }
  double seconds(Real sigma3) const {
    return 1e-9 * kMembraneStepOverCell * cell.ns_per_particle_step * cell.balls * steps(sigma3);
  }
};

}  // namespace

JobPlan plan_job(const PlanInput& in) {
  JobPlan plan;
  Stages add{plan, in.at_once};
  const CalibrateConfig& cc = in.cell.calibrate;
  const int factor = static_cast<int>(std::max(cc.cell_factor, 1L));
  Config cell = larger_cell(in.cell, factor);
  bool void_ratio = false;
  for (const auto& m : in.materials)
    for (const TriaxialTest& t : m.second) void_ratio = void_ratio || std::isfinite(t.void_ratio);
  // A matched state is prepared with a friction of its own: the packing then has a preparation stage.
  if (void_ratio && cell.periodic.prep_mu_s < 0) cell.periodic.prep_mu_s = 0.5 * cell.ball.mu_s;
  const CellCost lab = measure_cell_cost(cell);
  const CellCost check = measure_cell_cost(larger_cell(cell, kCellCheckFactor));
  const int S = static_cast<int>(cc.scatter_specimens);
  const bool auto_ensemble = cc.ensemble == kAutoEnsemble;
  const int K = auto_ensemble ? S : static_cast<int>(cc.ensemble);
  const int K_low = auto_ensemble ? 1 : K;
  const std::string n = std::to_string(lab.balls);
  const int match_packings = 2 + MatchPlan{}.steps;
  // What the packing store holds already: the match replayed on its packings, then the specimens at its friction.
  Config matched = in.cell;
  const bool match_stored = stored_match(in.cell, in.state_tests, match_plan(in.cell, in.at_once), matched);
  const Config lab_cell = larger_cell(matched, factor);
  const unsigned seed = in.cell.run.seed;
  if (match_stored && void_ratio)
    plan.notes.push_back("state match: its packings are in the packing store (preparation friction " +
                         fmt("%.4g", matched.periodic.prep_mu_s) + ")");
  if (void_ratio && !match_stored)
    add.packings("state match", "the data's void_ratio", lab, match_packings * kStateMatchSpecimens,
                 match_packings * kStateMatchSpecimens, kStateMatchSpecimens,
                 "up to " + std::to_string(match_packings) + " packings of " + std::to_string(kStateMatchSpecimens) +
                     " specimens");
  // The match's last packing is the first specimens'; with the match known, the store says which are left.
  const int shared = void_ratio ? kStateMatchSpecimens : 0;
  const int to_pack = match_stored ? S - stored_specimens(lab_cell, seed, S) : S - shared;
  add.packings("scatter specimens", "[calibrate] scatter_specimens", lab, to_pack, to_pack, to_pack,
               std::to_string(to_pack) + " packings");
  for (const auto& [material, tests] : in.materials) {
    const std::string T = std::to_string(tests.size());
    add.runs(material + ": scatter runs", "[calibrate] scatter_specimens", lab, tests, 1, S, S,
             std::to_string(S * static_cast<int>(tests.size())) + " runs of " + n + " balls (" + std::to_string(S) +
                 " specimens x " + T + " tests)");
    // The check cells' own state match starts from a bracket around the lab's friction (4 packings) and falls back
    // to the whole range (up to 2 + kCellCheckPrepSteps more). No check where the data's specimens have the cell's
    // balls (measure_cell_bias).
    const int check_low = 4, check_high = 4 + 2 + kCellCheckPrepSteps;
    const bool checked = std::any_of(tests.begin(), tests.end(), [&](const TriaxialTest& t) {
      return cell_bias_extrapolation(static_cast<Real>(lab.balls), kCellCheckFactor, t.specimen_balls) != 0;
    });
    if (!checked)
      plan.notes.push_back(material + ": the data's specimens have the cell's " + n + " balls: no cell's bias check");
    // The check's own match (measure_cell_bias' plan), replayed on the store where the lab's match is known.
    MatchPlan check_plan;
    check_plan.first_seed = seed + kCellCheckSeedOffset;
    check_plan.steps = kCellCheckPrepSteps;
    check_plan.workers = in.at_once;
    check_plan.around = std::sqrt(lab_cell.periodic.prep_mu_s);
    Config check_cell = larger_cell(lab_cell, kCellCheckFactor);
    const bool check_stored =
        match_stored && stored_match(larger_cell(lab_cell, kCellCheckFactor), tests, check_plan, check_cell);
    const int check_to_pack = check_stored ? kCellCheckSpecimens - stored_specimens(check_cell, check_plan.first_seed,
                                                                                    kCellCheckSpecimens)
                                           : kCellCheckSpecimens - shared;
    if (void_ratio && checked && !check_stored)
      add.packings(material + ": cell's bias check, state match", "the cell's bias check (kCellCheckFactor)", check,
                   check_low * kStateMatchSpecimens, check_high * kStateMatchSpecimens, kStateMatchSpecimens,
                   std::to_string(check_low) + " to " + std::to_string(check_high) + " packings of " +
                       std::to_string(kStateMatchSpecimens) + " specimens");
    if (checked) {
      add.packings(material + ": cell's bias check, specimens", "the cell's bias check (kCellCheckFactor)", check,
                   check_to_pack, check_to_pack, kCellCheckSpecimens, std::to_string(check_to_pack) + " packings");
      add.runs(material + ": cell's bias check, runs", "the cell's bias check (kCellCheckFactor)", check, tests, 1,
               kCellCheckSpecimens, kCellCheckSpecimens,
               std::to_string(kCellCheckSpecimens * static_cast<int>(tests.size())) + " runs of " +
                   std::to_string(check.balls) + " balls");
    }
    const long points = in.diagnose ? planned_points(in.free) + static_cast<long>(extensions().size()) * 6
                                    : planned_points(in.free);
    const std::string k = auto_ensemble ? "1 to " + std::to_string(K) : std::to_string(K);
    const std::string search_what = std::to_string(points) + " points x " + T + " tests x " + k + " specimens of " + n +
                                    " balls" + (in.diagnose ? " (the base model, then " +
                                                                  std::to_string(extensions().size()) + " extensions)"
                                                            : "");
    add.runs(material + (in.diagnose ? ": diagnosis" : ": search"), auto_ensemble ? "[calibrate] ensemble (auto)" : "[calibrate] ensemble",
             lab, tests, static_cast<double>(points), K_low, K, search_what);
    if (in.membrane) {
      const MembraneCost mem(*in.membrane);
      const int P = static_cast<int>(cc.predict_specimens);
      // Each specimen is built, then tested at every pressure, min(P, runs at once) specimens side by side.
      const int side = std::min(in.at_once, P);
      const double one = mean_over(tests, [&](Real s) { return mem.seconds(s); });
      const double build = kMembraneSpecimenOverTest * one, tests_one = one * static_cast<double>(tests.size());
      const double test_steps = mean_over(tests, [&](Real s) { return mem.steps(s); }) *
                                static_cast<double>(mem.cell.balls) * P;  // one pressure's, on every specimen
      const double T_n = static_cast<double>(tests.size());
      const std::string what = std::to_string(P * static_cast<int>(tests.size())) + " membrane tests of " +
                               std::to_string(mem.cell.balls) + " balls (" + std::to_string(P) + " specimens x " + T +
                               " pressures, " + std::to_string(side) +
                               " specimens at once; a specimen in .specimens is not built again)";
      const double each = wall(P, build + tests_one, side), tests_s = wall(P, tests_one, side);
      if (in.two_fidelity && !in.diagnose) {
        // 1 to kFidelityRounds rounds (two_fidelity_rounds), the specimens built in the first.
        const double R = kFidelityRounds;
        const std::string rounds = ", 1 to " + std::to_string(kFidelityRounds) + " rounds";
        // Where the rounds do not converge, once more at the last optimum (FidelityRounds::chosen); the prediction
        // takes the membrane runs made at its point.
        plan.stages.push_back({material + ": two fidelities, membrane tests",
                               what + rounds + ", once more where they do not converge",
                               "[calibrate] predict_specimens", test_steps * ((R + 1) * T_n + kMembraneSpecimenOverTest),
                               each, each + R * tests_s});
        add.runs(material + ": two fidelities, periodic runs", "[calibrate] scatter_specimens", lab, tests, 1, S, S,
                 std::to_string(S * static_cast<int>(tests.size())) + " runs of " + n + " balls" + rounds);
        upto_rounds(plan.stages.back());
        add.runs(material + ": search (corrected)", "[calibrate] ensemble", lab, tests, static_cast<double>(points),
                 K_low, K, search_what + rounds);
        upto_rounds(plan.stages.back());
      }
      // The specimens built for two fidelities are cached: the prediction tests only, the held-out pressures too.
      double held = 0;
      for (const TriaxialTest& t : in.held_out) held += t.material == material ? 1 : 0;
      const double with_held = tests_one * (T_n + held) / T_n;
      const double predict = wall(P, in.two_fidelity && !in.diagnose ? with_held : build + with_held, side);
      plan.stages.push_back({material + ": prediction", what + (held > 0 ? fmt(", %.0f held out", held) : ""),
                             "[calibrate] predict_specimens", test_steps * (T_n + held + kMembraneSpecimenOverTest),
                             predict, predict});
    } else if (in.walls) {
      const int P = static_cast<int>(cc.predict_specimens);
      add.runs(material + ": prediction (walls)", "[calibrate] predict_specimens", lab, tests, 1, P, P,
               std::to_string(P * static_cast<int>(tests.size())) + " runs of the walled cell of " + n + " balls");
    }
  }
  if (in.walls) {  // the walled cell's own preparation to the data's state, once for all materials
    const int P = static_cast<int>(cc.predict_specimens);
    if (void_ratio)
      add.packings("prediction (walls): state match", "the data's void_ratio", lab, match_packings * kStateMatchSpecimens,
                   match_packings * kStateMatchSpecimens, kStateMatchSpecimens,
                   "up to " + std::to_string(match_packings) + " packings of " + std::to_string(kStateMatchSpecimens) +
                       " specimens");
    add.packings("prediction (walls): specimens", "[calibrate] predict_specimens", lab, P - shared, P - shared, P,
                 std::to_string(std::max(0, P - shared)) + " packings");
  }
  plan.notes.push_back(fmt("speed measured here: %.0f ns a particle-step", lab.ns_per_particle_step) +
                       " in the cell of " + n + " balls, " + fmt("%.0f", check.ns_per_particle_step) + " in the check's of " +
                       std::to_string(check.balls) + "; " + std::to_string(in.at_once) +
                       (in.at_once > 1 ? " runs at once, one thread each" : " run at a time"));
  plan.notes.push_back(fmt("a run of %.0f steps", static_cast<double>(lab.run_steps(cell.periodic.triax.sigma3))) +
                       fmt(" at %g kPa", 1e-3 * cell.periodic.triax.sigma3) +
                       fmt(" (%.0f s)", lab.run_seconds(cell.periodic.triax.sigma3)) +
                       fmt(", a packing of %.0f steps", static_cast<double>(lab.packing_steps)) +
                       fmt(" (%.0f s)", lab.packing_seconds()) + ": estimates (host/lab/run_cost.hpp)");
  plan.notes.push_back("a search counts its planned points on the whole ensemble: one whose optimum lies on the edge "
                       "of a range searches again beyond it and runs more, and points far above the best run one "
                       "specimen only (Table 6's S-1 once ran 636 runs where 264 were planned, now 200)");
  if (auto_ensemble)
    plan.notes.push_back("ensemble \"auto\": the scatter runs choose 1 to " + std::to_string(S) +
                         " specimens a point (the fewest whose mean's standard error is half the data's noise): the "
                         "searches' times are that range");
  if (cc.cell_factor == kAutoCell && auto_ensemble)
    plan.notes.push_back("cell \"auto\": where all " + std::to_string(S) + " scatter specimens fall short, the cell "
                         "grows (up to " + std::to_string(kMaxCellFactor) + " x its balls) and every later stage costs "
                         "about that factor more: the job says so when it happens");
  plan.notes.push_back("packings in the packing store (" + in.cell.packing_store + ") are read, not packed, and not "
                       "counted above");
  return plan;
}

std::string JobPlan::text(const std::string& kind) const {
  std::string s = kind + ": plan (before any packing):\n";
  for (const PlanStage& p : stages)
    s += "  " + p.name + ": " + p.work + fmt(", %.2g particle-steps, ", p.particle_steps) + span(p.low, p.high) + "\n";
  s += kind + ": in all " + fmt("%.2g particle-steps, ", particle_steps()) + "about " + span(low(), high()) +
       " on this machine\n";
  for (const std::string& n : notes) s += "  " + n + "\n";
  return s;
}

}  // namespace dem
