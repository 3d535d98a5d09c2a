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
#include "host/util/text_format.hpp"

namespace dem {

/// A membrane specimen's build (layers compacted and settled) over one membrane test's steps: the README's small S-1
/// case builds its specimen in 3.5 minutes and runs the test in 2 min 45 s on 2 cores. A specimen is built once per
/// seed and cached (.specimens), then tested at every pressure.
constexpr Real kMembraneSpecimenOverTest = 1.3;

namespace {

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
                           c.seconds_of(low_n, c.packing_seconds(), k), c.seconds_of(n, c.packing_seconds(), k)});
  }
  /// Runs of `tests` on `low_k` to `k` specimens per point, `points` points one after another.
  void runs(const std::string& name, const std::string& setting, const CellCost& c,
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

/// What every stage of a plan reads: the job, the lab's cell and the check's, the specimens and the state match.
struct Planner {
  const PlanInput& in;
  JobPlan plan;
  Stages add{plan, in.at_once};
  const CalibrateConfig& cc = in.cell.calibrate;
  int factor = 1;
  Config cell;  ///< the lab's cell as the job grows it, with a preparation friction where matched
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

  explicit Planner(const PlanInput& input) : in(input) {
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

  /// A match's packings at the ends of [0, 1] (preparation_reach), in packings of a typical friction: the
  /// frictionless end's settling takes 2.3 to 3.6 times as many steps.
  static PackingCost match_ends() {
    const PackingCost none = packing_cost_at(0), full = packing_cost_at(1);
    return {none.low + full.low, none.high + full.high};
  }

  /// The state match's packings, where the store does not hold them: `name`'s stage.
  void match_packings_stage(const std::string& name) {
    const PackingCost ends = match_ends();
    const double halvings = match_packings - 2;
    add.packings(name, "the data's void_ratio", lab, (halvings + ends.low) * kStateMatchSpecimens,
                 (halvings + ends.high) * kStateMatchSpecimens, kStateMatchSpecimens,
                 "up to " + std::to_string(match_packings) + " packings of " + std::to_string(kStateMatchSpecimens) +
                     " specimens");
    note_ends();
  }

  /// Says once that a match's ends are counted at their own cost.
  void note_ends() {
    const std::string note = "a state match packs at preparation friction 0, where the balls slide on and settle in " +
                             fmt("%.1f", packing_cost_at(0).low) + " to " + fmt("%.1f", packing_cost_at(0).high) +
                             " times a packing's steps: counted so";
    if (std::find(plan.notes.begin(), plan.notes.end(), note) == plan.notes.end()) plan.notes.push_back(note);
  }

  /// The lab's own specimens: the state match and the scatter specimens.
  void specimens() {
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
  void bias_check(const std::string& material, const std::vector<TriaxialTest>& tests) {
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
    const int check_to_pack = check_stored ? kCellCheckSpecimens - stored_specimens(check_cell, check_plan.first_seed,
                                                                                    kCellCheckSpecimens)
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
    add.runs(material + ": cell's bias check, runs", setting, check, tests, 1, kCellCheckSpecimens,
             kCellCheckSpecimens,
             std::to_string(kCellCheckSpecimens * static_cast<int>(tests.size())) + " runs of " +
                 std::to_string(check.balls) + " balls");
  }

  /// A diagnosis's extension fits (6 points each) added to its stage, each priced on a cell with the extension at its
  /// middle strength: the Hertz extension's stiffer contacts take a smaller step, and priced at the base law's, the
  /// Hertz-Mindlin data's diagnosis took 1.5 times its plan (data/sweeps/plan/crosscode_diagnoses.txt).
  void extension_points(const std::vector<TriaxialTest>& tests) {
    const Model base = model_of(cell);
    PlanStage whole = plan.stages.back();
    for (const Extension& e : extensions_of(base)) {
      Model m = base;
      set_param(m, e.param, e.levels[std::min<std::size_t>(1, e.levels.size() - 1)]);
      CellCost c = searched;
      if (!same_model({m.law, 0}, {base.law, 0})) {  // a contact law of its own: its step and speed probed
        Config extended = cell;
        extended.ball = m.law;
        c = measure_cell_cost(extended);
        c.mu_s = searched.mu_s;
      }
      add.runs("", "", c, tests, 6, K_low, K, "");
      whole.particle_steps += plan.stages.back().particle_steps;
      whole.low += plan.stages.back().low;
      whole.high += plan.stages.back().high;
      plan.stages.pop_back();
    }
    plan.stages.back() = whole;
  }

  /// A material's membrane tests: two fidelities' rounds (with the periodic runs and the corrected search they
  /// repeat) where the job fits them, then the prediction, held-out pressures included.
  void membrane(const std::string& material, const std::vector<TriaxialTest>& tests, long points,
                const std::string& search_what) {
    const MembraneCost mem(*in.membrane);
    const int P = static_cast<int>(cc.predict_specimens);
    const std::string T = std::to_string(tests.size());
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
    const double each = side_by_side_seconds(P, build + tests_one, side);
    const double tests_s = side_by_side_seconds(P, tests_one, side);
    const bool rounds_run = in.two_fidelity && !in.diagnose;
    if (rounds_run) {
      // 1 to kFidelityRounds rounds (two_fidelity_rounds), the specimens built in the first.
      const double R = kFidelityRounds;
      const std::string rounds = ", 1 to " + std::to_string(kFidelityRounds) + " rounds";
      // Where the rounds do not converge, once more at the last optimum (FidelityRounds::chosen); the prediction
      // takes the membrane runs made at its point.
      plan.stages.push_back({material + ": two fidelities, membrane tests",
                             what + rounds + ", once more where they do not converge", "[calibrate] predict_specimens",
                             test_steps * ((R + 1) * T_n + kMembraneSpecimenOverTest), each, each + R * tests_s});
      add.runs(material + ": two fidelities, periodic runs", "[calibrate] scatter_specimens", searched, tests, 1, S, S,
               std::to_string(S * static_cast<int>(tests.size())) + " runs of " + n + " balls" + rounds);
      upto_rounds(plan.stages.back());
      add.runs(material + ": search (corrected)", "[calibrate] ensemble", searched, tests, static_cast<double>(points),
               K_low, K, search_what + rounds);
      upto_rounds(plan.stages.back());
    }
    // The specimens built for two fidelities are cached: the prediction tests only, the held-out pressures too.
    double held = 0;
    for (const TriaxialTest& t : in.held_out) held += t.material == material ? 1 : 0;
    const double with_held = tests_one * (T_n + held) / T_n;
    const double predict = side_by_side_seconds(P, rounds_run ? with_held : build + with_held, side);
    plan.stages.push_back({material + ": prediction", what + (held > 0 ? fmt(", %.0f held out", held) : ""),
                           "[calibrate] predict_specimens", test_steps * (T_n + held + kMembraneSpecimenOverTest),
                           predict, predict});
  }

  /// A material's compression tests (--compression), each on every scatter specimen at the base, then on the
  /// ensemble at every point of the search and at a calibration's answer (host/study/calibration_jobs.cpp); a
  /// diagnosis's points are its base fit's and its extension fits' (host/fit/diagnose.cpp).
  void compressions(const std::string& material, long points) {
    std::vector<CompressionTest> tests;
    for (const CompressionTest& t : in.compression)
      if (t.material == material) tests.push_back(t);
    if (tests.empty()) return;
    const double T = static_cast<double>(tests.size());
    double low = 0, high = 0;  // a test's mean steps
    for (const CompressionTest& t : tests) {
      low += static_cast<double>(searched.compression_steps(t.stress.size(), false)) / T;
      high += static_cast<double>(searched.compression_steps(t.stress.size())) / T;
    }
    const double step_s = 1e-9 * searched.ns_per_particle_step * static_cast<double>(searched.balls);
    const auto seconds = [&](double points_n, int k, double steps) {
      return points_n * searched.seconds_of(T * k, steps * step_s, in.at_once);
    };
    const double at = static_cast<double>(points + (in.diagnose ? 0 : 1));  // the points, and a calibration's answer
    plan.stages.push_back(
        {material + ": compression tests",
         std::to_string(tests.size()) + " tests x (" + std::to_string(S) + " specimens at the base + " +
             std::to_string(points) + (in.diagnose ? " points x " : " points and the answer x ") +
             (auto_ensemble ? "1 to " + std::to_string(K) : std::to_string(K)) +
             " specimens) of " + n + " balls, a hold a load step",
         "--compression", T * (S + at * K) * high * static_cast<double>(searched.balls),
         seconds(1, S, low) + seconds(at, K_low, low), seconds(1, S, high) + seconds(at, K, high)});
  }

  /// A material's stages: its scatter runs, the cell's bias check, the search, and what predicts.
  void material(const std::string& material, const std::vector<TriaxialTest>& tests) {
    const std::string T = std::to_string(tests.size());
    add.runs(material + ": scatter runs", "[calibrate] scatter_specimens", lab, tests, 1, S, S,
             std::to_string(S * static_cast<int>(tests.size())) + " runs of " + n + " balls (" + std::to_string(S) +
                 " specimens x " + T + " tests)");
    bias_check(material, tests);
    const long tried = in.diagnose ? static_cast<long>(extensions_of(model_of(in.cell)).size()) : 0;
    const bool one = one_specimen();
    const long points = (one ? planned_one_specimen_points(static_cast<int>(in.free.size()))
                             : planned_points(static_cast<int>(in.free.size()))) + tried * 6;
    const std::string k = one ? "1" : auto_ensemble ? "1 to " + std::to_string(K) : std::to_string(K);
    const std::string search_what = std::to_string(points) + " points x " + T + " tests x " + k + " specimens of " + n +
                                    " balls" + (in.diagnose ? " (the base model, then " +
                                                                  std::to_string(tried) + " extensions)"
                                                            : "");
    add.runs(material + (in.diagnose ? ": diagnosis" : ": search"),
             one ? "[calibrate] method" : auto_ensemble ? "[calibrate] ensemble (auto)" : "[calibrate] ensemble",
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

  /// The walled cell's own preparation to the data's state, once for all materials.
  void walls_specimens() {
    const int P = static_cast<int>(cc.predict_specimens);
    if (void_ratio) match_packings_stage("prediction (walls): state match");
    add.packings("prediction (walls): specimens", "[calibrate] predict_specimens", lab, P - shared, P - shared, P,
                 std::to_string(std::max(0, P - shared)) + " packings");
  }

  /// Whether the search runs one specimen a point ([calibrate] method; diagnose and two fidelities search with the
  /// ensemble).
  bool one_specimen() const { return cc.one_specimen() && !in.diagnose && !in.two_fidelity; }

  /// What the counts rest on: the speed measured, a run's and a packing's steps, and the choices made on the way.
  void notes() {
    const auto probed = [](const CellCost& c) {
      return c.probed_balls < c.balls ? " (probed on a lattice of " + std::to_string(c.probed_balls) + ")" : std::string();
    };
    plan.notes.push_back(fmt("speed measured here: %.0f ns a particle-step", lab.ns_per_particle_step) +
                         " in the cell of " + n + " balls" + probed(lab) + ", " +
                         fmt("%.0f", check.ns_per_particle_step) + " in the check's of " +
                         std::to_string(check.balls) + probed(check) + "; " +
                         (lab.batch > 1
                              ? "runs in batches of up to " + std::to_string(lab.batch) +
                                    fmt(", each cell adding %.3g of a run's time to its batch", lab.batch_growth)
                              : std::to_string(in.at_once) +
                                    (in.at_once > 1 ? " runs at once, one thread each" : " run at a time")));
    plan.notes.push_back(fmt("a run of %.0f steps", static_cast<double>(lab.run_steps(cell.periodic.triax.sigma3))) +
                         fmt(" at %g kPa", 1e-3 * cell.periodic.triax.sigma3) +
                         fmt(" (%.0f s)", lab.run_seconds(cell.periodic.triax.sigma3)) +
                         fmt(", a packing of %.0f steps", static_cast<double>(lab.packing_steps)) +
                         fmt(" (%.0f s)", lab.packing_seconds()) + ": estimates (host/lab/run_cost.hpp)");
    if (lab.resettles())
      plan.notes.push_back(fmt("the base's sliding friction %g", static_cast<double>(lab.mu_s)) +
                           " lets the balls slide on at sigma3: a run's consolidation settles its packing again, "
                           "counted as " + fmt("%g", static_cast<double>(ResettleCost::low)) +
                           fmt(" to %g packings' steps (measured 0.56 to 18.5: a frictionless packing is marginally rigid)", static_cast<double>(ResettleCost::high)));
    if (one_specimen())
      plan.notes.push_back("one specimen a point ([calibrate] method): the search runs its design and up to " +
                           std::to_string(OneSpecimenSearch{}.rounds) + " rounds once each, on one specimen; the "
                           "scatter runs at the base and at the answer are its points there; an optimum on the edge "
                           "of a range searches again beyond it and runs more");
    else
      plan.notes.push_back("a search counts its planned points on the whole ensemble: one whose optimum lies on the "
                           "edge of a range searches again beyond it and runs more, and points far above the best run "
                           "one specimen only (Table 6's S-1 once ran 636 runs where 264 were planned, now 200)");
    if (auto_ensemble && !one_specimen())
      plan.notes.push_back("ensemble \"auto\": the scatter runs choose 1 to " + std::to_string(S) +
                           " specimens a point (the fewest whose mean's standard error is half the data's noise): "
                           "the searches' times are that range");
    if (cc.cell_factor == kAutoCell && auto_ensemble && !one_specimen())
      plan.notes.push_back("cell \"auto\": where all " + std::to_string(S) + " scatter specimens fall short, the "
                           "cell grows (up to " + std::to_string(kMaxCellFactor) + " x its balls) and every later "
                           "stage costs about that factor more: the job says so when it happens");
    plan.notes.push_back("packings in the packing store (" + in.cell.packing_store + ") are read, not packed, and "
                         "not counted above");
  }
};

}  // namespace

JobPlan plan_job(const PlanInput& in) {
  Planner p(in);
  p.specimens();
  for (const auto& [material, tests] : in.materials) p.material(material, tests);
  if (in.walls) p.walls_specimens();
  p.notes();
  return p.plan;
}

}  // namespace dem
