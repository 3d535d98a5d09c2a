#pragma once
/// The two-fidelity calibration: the periodic cell drives the search, and the membrane test, the test
/// the lab ran, corrects it. At the periodic optimum both run at every pressure of the data; their difference in
/// each compared feature (the membrane test's specimens against the periodic ensemble, in the q the data report)
/// is the discrepancy the boundary makes. The periodic cell is then calibrated again against the data less that
/// discrepancy, its uncertainty counted in the misfit (Misfit::add_discrepancy), so that it reaches the
/// intervals. The discrepancy is taken as constant near the optimum it was measured at; it is not constant over the
/// parameters (the boundary's share of q grew from 24-32% to 30-36% as S-1's friction fell from the periodic to the
/// corrected optimum), so the correction is repeated at each new optimum until the optimum stops moving
/// (two_fidelity_rounds): a fixed point of "measure the discrepancy here, calibrate to the data less it", where the
/// membrane test at the optimum reads the data's values within the periodic cell's fit. Kennedy & O'Hagan (2000)
/// call the idea autoregressive co-kriging (z_t = rho z_(t-1) + delta_t, a cheap model corrected towards a costly
/// one); here the correction is a measured offset per feature, not a fitted process (docs/calibration.md, The
/// reference test).
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "host/fit/calibrate.hpp"
#include "host/fit/misfit.hpp"
#include "host/fit/prediction.hpp"

namespace dem {

/// The membrane test's excess over the periodic cell in each feature of the misfit, with its standard error.
struct Discrepancy {
  std::vector<std::vector<Real>> delta, sd;  ///< [test][feature], the feature's unit (Pa for q)
  /// The membrane test's own chi2 against the data as measured (its specimens' mean, in the misfit's noise): how well
  /// the test the lab ran fits where it was run, whatever the cell reads there.
  Real membrane_chi2 = std::numeric_limits<Real>::quiet_NaN();
};

/// The base config with the cell of the reference test: `cli` (--reference-test), else the base config's
/// [calibrate] reference_test; "walls" puts the cell between six walls ([periodic] boundary, host/triax/cell_boundary.hpp);
/// --reference-test periodic or two_fidelity makes it periodic; the config's own periodic or two_fidelity keep its
/// boundary.
Config reference_cell(const Config& base, const std::string& cli);

/// Whether the calibration fits two fidelities: `cli` (--reference-test), else the base config's [calibrate]
/// reference_test. Two fidelities need a membrane test to predict with (`membrane`) on at least 2 specimens;
/// ConfigError names the key before any run.
bool two_fidelity_wanted(const Config& base, const std::string& cli, bool membrane);

/// Two fidelities correct the cell toward the membrane test of `membrane`, so that test must be the data's: where a
/// test gives specimen_balls, the template's specimen must have them within kTemplateSizeTolerance. ConfigError
/// names `key` (where the template came from), both sizes and the ways out, before any run.
void check_template_size(const Config& membrane, const std::vector<TriaxialTest>& tests, const std::string& key);
/// Refuses (ConfigError naming `key`, both files and both laws) a membrane template whose ball-ball contact law is not
/// the base's: two fidelities correct the cell by the template's test at the cell's parameters, which another law reads
/// otherwise (a hertz_mindlin template beside an rrlinear base ran its loop to a "fixed point" of two models).
void check_template_law(const Config& base, const Config& membrane, const std::string& key);
/// A quarter: the boundary's share goes as N^-1/3, so a specimen 25% larger or smaller changes it by under 8%.
inline constexpr Real kTemplateSizeTolerance = 0.25;

/// Whether a feature is a stress (q at a strain; E_ini, q_1pct, q_3pct, q_peak, q_end): the boundary scales it
/// (the bulge's area, the walls' layer), so the discrepancy is taken as a ratio; strains (eps_v, eps_a at the peak,
/// dilatancy) take it as a difference.
bool scales_with_stress(const Feature& f);

/// Per feature of `misfit`, with m and p the means over the membrane test's specimens and the periodic ensemble:
/// for a stress, the cell reads rho = p / m of the membrane test, and the datum y is corrected by
/// delta = (1 - rho) y; for a strain, delta = m - p. sd from the two sets' sample scatter s_m, s_p over K_m, K_p
/// specimens: |rho y| sqrt(s_m^2 / (K_m m^2) + s_p^2 / (K_p p^2)) or sqrt(s_m^2 / K_m + s_p^2 / K_p) (K_m, K_p >= 2;
/// a set of one gives no scatter and is refused). `membrane[k].members` and `periodic[k]` run test k of the misfit.
Discrepancy measure_discrepancy(const Misfit& misfit, const std::vector<Prediction>& membrane, const Ensemble& periodic);

/// The discrepancy in words for the report: per test, the cell's ratio to the membrane test and the correction of the
/// data's q with its sd (kPa), means over the compared stresses (E_ini left out).
std::string discrepancy_text(const Misfit& misfit, const Discrepancy& d, const std::vector<TriaxialTest>& tests);

/// One round of two fidelities: the discrepancy measured at `at`, and the periodic cell calibrated to the data
/// less it.
struct FidelityRound {
  std::vector<Real> at;      ///< where the membrane test measured the discrepancy (SI, in the free parameters' order)
  bool secant = false;       ///< `at` is a secant step through the two rounds before, not the last optimum
  std::string discrepancy;   ///< discrepancy_text of the round
  CalibrationResult fit;     ///< the corrected calibration
  /// How far `at` lies from the corrected optimum, in widths of its joint 95% region (CalibrationResult::region_rise's
  /// metric; in one parameter, of its 95% interval): the fixed point's residual, zero where the discrepancy was
  /// measured at the optimum it gives, and small along a ridge the data leave free.
  Real moved = 0;
  Real membrane_chi2 = std::numeric_limits<Real>::quiet_NaN();  ///< the membrane test's at `at` (Discrepancy)
};

/// Rounds until the corrected optimum lies within kFixedPointMove of its joint 95% region's width of where its
/// discrepancy was measured (a tenth: within the interval's own uncertainty, as significant_gain's fifth of a radius), at most
/// kFidelityRounds. The plain iteration (measure at the last optimum) contracts by F' = d optimum / d at a round,
/// about -0.3 for S-1's boundary share, which against intervals a tenth of the first move needs five rounds; from the
/// third round on, each parameter takes the secant step through the last two rounds (Steffensen's idea: a
/// discrepancy linear in the parameters near the optimum, the suggestion), which lands on the fixed point of
/// a linear map in one step.
struct FidelityRounds {
  std::vector<FidelityRound> rounds;
  bool converged = false;
  /// Not converged, with the membrane test as the reference (the issue's "the search's last points run the membrane
  /// test itself"): the membrane test run at the last optimum too (its chi2 here), and the point among the rounds'
  /// and that one where the membrane test fits the data as measured best becomes the answer: the membrane test's own
  /// optimum among the points it ran, near the fixed point, at no search of its own. NaN where converged.
  Real last_membrane_chi2 = std::numeric_limits<Real>::quiet_NaN();
  std::size_t chosen = 0;      ///< the answer's point: a round's index (its `at`), or rounds.size() for the last optimum
  CalibrationResult answer;    ///< the last round's fit, or, moved to the chosen round's point, adopt_best there
  const CalibrationResult& last() const { return answer; }
  /// Every round in words, and whether the optimum reached its fixed point ("mu_s 0.105 [0.085, 0.189] ...").
  std::string text() const;
};
inline constexpr int kFidelityRounds = 3;
inline constexpr Real kFixedPointMove = 0.1;

/// The discrepancy at a model (the membrane test's specimens and the periodic ensemble run there).
using DiscrepancyAt = std::function<Discrepancy(const Model&)>;
/// A calibration of the periodic cell against a misfit (the search, with its progress).
using CalibrateTo = std::function<CalibrationResult(const Misfit&)>;
/// The periodic cell's ensemble at a model against a misfit, as the search evaluates a point (its u left empty).
using EvaluateAt = std::function<Evaluation(const Model&, const Misfit&)>;

/// The point the membrane test fits best: the index of the round whose `at` has the lowest membrane chi2, or
/// rounds.size() for the last optimum (`last_chi2`), which wins ties: it is the fixed-point iteration's own answer.
std::size_t membrane_choice(const std::vector<FidelityRound>& rounds, Real last_chi2);

/// From `periodic`, the calibration against the data as measured: each round measures the discrepancy at the last
/// optimum (from the third round, the secant point of the last two), and calibrates to `misfit` (the data as
/// measured) less it; the rounds stop at the fixed point or after `max_rounds` (not converged: the last round's
/// optimum is the answer, and the report says so; with `evaluate`, the membrane test runs at the last optimum too and
/// the answer is the point it fits best, FidelityRounds::chosen). The membrane test runs once a round, at the
/// optimum it starts from; the prediction at the answer is the caller's.
FidelityRounds two_fidelity_rounds(const CalibrationResult& periodic, const Misfit& misfit,
                                   const std::vector<TriaxialTest>& tests, const DiscrepancyAt& measure,
                                   const CalibrateTo& fit, const std::string& template_path,
                                   int max_rounds = kFidelityRounds, const EvaluateAt& evaluate = {});

}  // namespace dem
