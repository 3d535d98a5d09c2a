/// The plan's runs beyond the search (host/fit/job_planner.hpp): a diagnosis's extension fits, the compression tests
/// and the membrane tests (two fidelities' rounds and the prediction).
#include <algorithm>

#include "host/fit/diagnose.hpp"
#include "host/fit/job_planner.hpp"
#include "host/fit/two_fidelity.hpp"
#include "host/util/text_format.hpp"

namespace dem::job_planning {

namespace {

/// A membrane specimen's build (layers compacted and settled) over one membrane test's steps: the README's small S-1
/// case builds its specimen in 3.5 minutes and runs the test in 2 min 45 s on 2 cores. A specimen is built once per
/// seed and cached (.specimens), then tested at every pressure.
constexpr Real kMembraneSpecimenOverTest = 1.3;

/// A stage repeated 1 to kFidelityRounds times: its time at the lower end once, its work and upper end every round.
void upto_rounds(PlanStage& p) {
  p.particle_steps *= kFidelityRounds;
  p.high *= kFidelityRounds;
}

}  // namespace

/// A diagnosis's extension fits (6 points each) added to its stage, each priced on a cell with the extension at its
/// middle strength: the Hertz extension's stiffer contacts take a smaller step, and priced at the base law's, the
/// Hertz-Mindlin data's diagnosis took 1.5 times its plan (data/sweeps/plan/crosscode_diagnoses.txt).
void Planner::extension_points(const std::vector<TriaxialTest>& tests) {
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
void Planner::membrane(const std::string& material, const std::vector<TriaxialTest>& tests, long points,
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
void Planner::compressions(const std::string& material, long points) {
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
  plan.stages.push_back({material + ": compression tests",
                         std::to_string(tests.size()) + " tests x (" + std::to_string(S) + " specimens at the base + " +
                             std::to_string(points) + (in.diagnose ? " points x " : " points and the answer x ") +
                             (auto_ensemble ? "1 to " + std::to_string(K) : std::to_string(K)) + " specimens) of " + n +
                             " balls, a hold a load step",
                         "--compression", T * (S + at * K) * high * static_cast<double>(searched.balls),
                         seconds(1, S, low) + seconds(at, K_low, low), seconds(1, S, high) + seconds(at, K, high)});
}

}  // namespace dem::job_planning
