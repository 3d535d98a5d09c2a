#pragma once
/// The misfit between measured tests and the simulator's ensemble: what is compared, with which
/// noise, and the whitened residuals that calibration and diagnosis minimise.
///
/// What is compared. Curve data: q and eps_v at the strains of kFeatureStrains (log-spaced, where the stiffness
/// and the early contraction live, then through the peak to the end), each read off a curve by a local
/// straight-line fit over +-min(30%, 0.25% strain) of the strain (curve_value), for measured and simulated
/// curves alike; a strain is used when both curves reach it. Summary data: the seven quantities of summarise.
///
/// With which noise, per test (three kinds of scatter kept apart and added: the measurement's, the measured
/// specimen's from its population, the simulator's mean's; docs/calibration.md, The misfit):
///   Sigma = Sigma_data + Sigma_specimen + Sigma_ensemble / K + Sigma_cell
///   Sigma_data      the measured curve's own noise: its standard-deviation columns, or, without them, the
///                   scatter of its rows about a smooth curve (row_noise, with the lag-1 correlation along
///                   strain counted: a window of n rows counts n (1 - rho) / (1 + rho)); zero where replicates
///                   give the specimen term, which holds it.
///   Sigma_specimen  the measured specimen is one specimen: from replicates when the data have them (the pooled
///                   scatter between replicates, q relative to sigma3), else as variable as one specimen of the
///                   simulator's ensemble, times (N_sim / N)^kSpecimenScatterExponent where the data say their
///                   specimen has N particles (specimen_balls); without N, a conservative stand-in
///                   for a larger specimen. Never below a lab's specimen scatter (LabCurveNoise: q_shared of q,
///                   ev_abs on eps_v): a real specimen differs from the next by more than its particle count.
///   Sigma_ensemble  the simulator's specimen-to-specimen covariance, measured once at the base model on the
///                   scatter specimens (more than the K of the ensemble): per-feature variances pooled over the
///                   tests (q in units of sigma3, eps_v as it is), correlated along strain as
///                   exp(-|ln e1 - ln e2| / l), l fitted to the specimens. A variance estimated from S specimens
///                   has S - 1 degrees of freedom (the tests share the specimens, so pooling over tests adds
///                   none); a deviation measured against it follows Student's t, whose variance is
///                   nu / (nu - 2) times the estimate: the estimate is inflated by that factor.
///   Sigma_cell      the simulator's finite-cell bias against the data's specimen (host/fit/cell_bias.hpp), measured
///                   by measure_misfit on larger cells, correlated along strain as Sigma_ensemble.
/// Tests are independent of each other. The `lab` noise replaces the data and specimen terms by a lab's
/// scatter (LabCurveNoise); summary data use NoiseModel, with the ensemble's variance added.
/// The residuals are whitened per test, r = L^-1 (mean of the members - measured), Sigma = L L^T, so that
/// chi2 = sum r^2 is about the number of data for a model right within the noise.
#include <array>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "host/data/curve_reading.hpp"
#include "host/data/measured.hpp"
#include "host/config/noise_model.hpp"
#include "host/lab/periodic_lab.hpp"

namespace dem {

/// The quantities of a test (NaN where absent).
std::array<Real, kQuantities> quantities(const TriaxialTest& t);

/// The simulator's standard error that an ensemble aims below, as a share of the data's noise: its mean then adds
/// at most a quarter to the variance.
constexpr Real kEnsembleRatioGoal = 0.5;

/// A periodic cell of N balls scatters from the next as N^-kSpecimenScatterExponent, which scales the simulator's
/// measured scatter to a data specimen of another size: the exponent of independent fluctuations. Between cells of
/// 120 and 1920 balls of this simulator (perf/specimen_scatter.sh: 12-16 specimens a size, 100 and 300 kPa, q and
/// eps_v at nine strains to 8%), two sets of specimens gave 0.44 and 0.58 on average, and q at 8% from both sets
/// together 0.45 (100 kPa) and 0.49 (300 kPa): one set's exponents scatter by about 0.15 either way, and 1/2 stands.
constexpr Real kSpecimenScatterExponent = 0.5;

/// The largest cell an "auto" cell grows to, in multiples of the config's balls: a run's cost grows with it.
constexpr int kMaxCellFactor = 8;

/// Residual of a datum the simulation could not produce (no peak, a blow-up): ten standard deviations.
constexpr Real kMissingResidual = 10;

/// Whitened residuals of one summary test against one simulated test with lab noise, one per quantity (NaN where
/// the measured test lacks it). L is lower triangular in quantity order: r_q is what datum q says beyond the
/// quantities before it (E_ini first), the shared specimen factor counted once.
std::array<Real, kQuantities> test_residuals(const TriaxialTest& measured, const TriaxialTest& simulated,
                                             const NoiseModel& noise);

/// How the data's noise is taken: "data" (standard-deviation columns, else replicates, else the curves'
/// own scatter; the lab model where none of these is possible) or "lab" (the lab model: the defaults, or a file's).
struct NoiseOptions {
  std::string mode = "data";
  LabCurveNoise lab;
  NoiseModel summary;
  std::string lab_name = "the lab model";  ///< how the report names the lab model (a file's path when read from one)
};
/// The lab noise of a file (`--noise FILE`, read_lab_noise) as the noise options of mode "lab".
NoiseOptions lab_noise_options(const std::string& path);

/// One compared datum of a test, with the parts of its noise (standard deviations, in its unit: Pa or -).
struct Feature {
  std::string name;          ///< "q at 0.1%", "eps_v at 2%", or a summary quantity's name
  int quantity = 0;          ///< 0: q, 1: eps_v; summary data: the Quantity
  Real strain = 0;           ///< curve features
  Real measured = 0;
  Real data_sd = 0, specimen_sd = 0, ensemble_sd = 0;  ///< ensemble_sd: one member's; the mean's is / sqrt(K)
  Real cell_sd = 0;  ///< the simulator's finite-cell bias against the data's specimen (host/fit/cell_bias.hpp)
  /// The uncertainty of the measured discrepancy between the reference test and this simulator (add_discrepancy).
  Real discrepancy_sd = 0;
  /// The data side's noise: the measured curve's and the measured specimen's, what the simulator's parts are set
  /// against.
  Real data_noise() const { return std::hypot(data_sd, specimen_sd); }
};

/// A quantity in the unit of the tables: MPa for the stiffness, kPa for stresses, % for the strain.
std::pair<double, const char*> in_table_unit(int q, Real v);
/// A feature's value and unit in the tables: q in kPa, eps_v in %, summary quantities in_table_unit.
std::pair<double, const char*> feature_unit(const Feature& f, Real v);
/// The quantity a feature belongs to, as the report groups them: "q" and "eps_v" for a curve's, a summary
/// quantity's name.
std::string quantity_group(const Feature& f);

/// The simulator's finite-cell bias as measured (host/fit/cell_bias.hpp): a standard deviation per test and
/// feature, and how it was measured, in words.
struct CellBias {
  std::vector<std::vector<Real>> sd;
  std::string note;
  /// Where the bias exceeds the data's noise (a quantity's median over its data): which quantities, by how much, the
  /// likely cause and the setting that removes it, for the report's first lines; empty otherwise.
  std::string finding;
};

/// The noise budget of one material's data, decided once (decide_noise_budget) and then only read: the simulator's
/// scatter, the ensemble and the cell it chose, the state its specimens were matched to on that cell, and the cell's
/// bias. The misfit is built from it and the report prints it; neither runs the simulator.
struct NoiseBudget {
  Ensemble scatter;      ///< the scatter specimens at the base model on the final cell, [test][specimen]
  /// Empty, or the same specimens at another model: each feature's simulator variance is then the larger of the two
  /// (Misfit::with_scatter keeps the base model's as this floor).
  Ensemble scatter_floor;
  int members = 1;       ///< the ensemble whose mean is compared
  int cell_factor = 1;   ///< the cell's balls as a multiple of the config's
  Real sim_balls = 0;    ///< particles in a simulator specimen (0: not given)
  Real sim_end = 0;      ///< the simulator's last axial strain
  StateMatch state;      ///< the data's state as matched on the final cell (tests 0: none matched)
  CellBias cell_bias;    ///< empty: not measured
};

/// The scatter specimens' word on the noise a calibration's answer carries (host/fit/calibrate.hpp, the intervals
/// measured on the specimens): the modelled Sigma's specimen and ensemble terms assume a shape (q and eps_v apart,
/// each correlated along strain by one kernel) that one specimen's departure need not have; these are that departure
/// as the specimens show it, in the misfit's whitened units.
struct SpecimenSpread {
  /// Per scatter specimen, its departure from the specimens' mean (all tests, whitened as the residuals are), scaled
  /// to the data specimen's term (the specimen's scale over one member's, as the misfit scales it; zero where that
  /// term is a lab's or the replicates'). A data specimen is one specimen a test: only the blocks of each test count.
  std::vector<std::vector<Real>> specimen;
  /// The same departures scaled to the ensemble mean's term (1 / sqrt(K)): the ensemble's members are the same
  /// packings at every pressure, so their departures count across tests too.
  std::vector<std::vector<Real>> ensemble;
  /// The first datum of each test, and the number of data after the last.
  std::vector<int> tests;
  /// Both terms as the misfit models them, whitened: data() x data(), row-major, zero between tests.
  std::vector<Real> modelled;
};

class Misfit {
 public:
  /// The misfit of a decided noise budget: its scatter, ensemble and cell bias.
  Misfit(const std::vector<TriaxialTest>& measured, const NoiseOptions& noise, const NoiseBudget& budget);
  /// `reference`: runs at the base model on the scatter specimens ([test][specimen], tests as in `measured`),
  /// which measure the simulator's scatter; `members`: the ensemble size whose mean is compared; `sim_end`: the
  /// simulator's last axial strain.
  /// `sim_balls`: particles in a simulator specimen, against which a test's specimen_balls scales its specimen
  /// term.
  /// `floor`: empty, or another scatter of the same specimens whose variance each feature keeps at least.
  Misfit(const std::vector<TriaxialTest>& measured, const NoiseOptions& noise, const Ensemble& reference,
         int members, Real sim_end, Real sim_balls = 0, const Ensemble& floor = {});
  std::size_t tests() const { return features_.size(); }
  int data() const;                               ///< compared data in all tests
  int data(std::size_t test) const { return static_cast<int>(features_[test].size()); }
  const std::vector<Feature>& features(std::size_t test) const { return features_[test]; }
  /// Whitened residuals of test k against its members' runs.
  std::vector<Real> test_residuals(std::size_t k, const std::vector<TriaxialTest>& members) const;
  /// All tests', concatenated in test order.
  std::vector<Real> residuals(const Ensemble& sim) const;
  /// The standard deviation of feature i of test k: every term of Sigma on its diagonal, as the residuals whiten.
  Real sd(std::size_t k, std::size_t i) const {
    return std::sqrt(cov_[k][i * features_[k].size() + i]);
  }
  /// The expected square norm of the change in the whitened residuals (all tests) when one member stands for the
  /// mean of the ensemble: (1 - 1/K) sum over tests of tr(Sigma^-1 Sigma_member), Sigma_member one member's
  /// scatter as Sigma counts it (correlated along strain where it is). A search that runs a point on one member
  /// first (calibrate.hpp, screening) reads that member's residuals with this spread.
  Real member_spread() const;
  /// The members' mean feature values of test k (NaN where no member has one).
  std::vector<Real> mean_values(std::size_t k, const std::vector<TriaxialTest>& members) const;
  /// What noise was used, per test and in words, for the report.
  const std::vector<std::string>& notes() const { return notes_; }
  /// The cell's bias where it exceeds the data's noise (CellBias::finding): a set-up error to report first.
  const std::string& cell_bias_finding() const { return cell_finding_; }
  std::string source() const { return source_; }
  Real correlation_length() const { return length_; }
  /// The simulator's standard error over the data-side noise, median over the data: the ensemble is large
  /// enough when it is below 1/2 (its mean then adds at most a quarter to the variance).
  Real ensemble_ratio() const;
  /// The ensemble size that brings ensemble_ratio() to `target` (the standard error goes as 1 / sqrt(K)).
  int members_for(Real target) const;
  int members() const { return members_; }
  /// Particles in a simulator specimen (0: not given).
  Real sim_balls() const { return sim_balls_; }
  /// Two fidelities (host/fit/two_fidelity.hpp): the data are what the reference test measures, which exceeds what this
  /// simulator gives at the same parameters by delta[test][feature]; the simulator is then compared with the data
  /// less delta, and delta's uncertainty sd[test][feature] is counted, correlated along strain as a bias is.
  void add_discrepancy(const std::vector<std::vector<Real>>& delta, const std::vector<std::vector<Real>>& sd,
                       const std::string& note);
  /// The scatter specimens' mean void ratio at the start of shear of test k, at the base model.
  Real reached_void_ratio(std::size_t k) const { return void_ratio_[k]; }
  /// The same misfit with the simulator's scatter measured also on `scatter` ([test][specimen]: the scatter specimens
  /// run at another model, the calibrated one): each feature's specimen and ensemble terms take the larger of the two
  /// scatters; the data's noise, the ensemble and the cell's bias stay. Only for a misfit built from a noise budget,
  /// before any discrepancy is added.
  /// `members` > 0: and the simulator's mean counted as that of so many specimens (one specimen a point: the ensemble the
  /// surfaces are worth at the answer, CalibrationResult::surrogate_members).
  Misfit with_scatter(const Ensemble& scatter, int members = 0) const;
  /// The same misfit with the simulator's mean counted as that of `members` specimens (one specimen a point searches
  /// with 1: each run is one specimen). Only for a misfit built from a noise budget, before any discrepancy.
  Misfit with_members(int members) const;
  /// The noise budget it was built from (empty where it was built from a reference ensemble).
  const NoiseBudget& budget() const { return budget_; }
  /// The specimen spreads of the scatter this misfit was built from (a noise budget's): its scatter specimens' and,
  /// after with_scatter, those of the scatter it keeps as a floor. Empty for a misfit not built from a budget, or
  /// whose scatter has fewer than kMinSpreadSpecimens specimens.
  std::vector<SpecimenSpread> specimen_spreads() const;

 private:
  /// What built it, for with_scatter: set by the budget's constructor, cleared by add_discrepancy.
  std::vector<TriaxialTest> measured_;
  NoiseOptions noise_;
  NoiseBudget budget_;
  bool from_budget_ = false;
  std::vector<Real> void_ratio_;
  std::string cell_finding_;
  /// Sigma_cell: adds the simulator's finite-cell bias (host/fit/cell_bias.hpp), each test's correlated along
  /// strain as the ensemble's scatter is (a bias moves a curve smoothly); its note goes to notes().
  void add_cell_bias(const CellBias& bias);
  std::vector<Real> values(std::size_t k, const TriaxialTest& t) const;
  void build_curve_noise(const std::vector<TriaxialTest>& measured, const NoiseOptions& noise, const Ensemble& ref,
                         Real sim_balls, const Ensemble& floor);
  void build_summary_noise(const std::vector<TriaxialTest>& measured, const NoiseOptions& noise, const Ensemble& ref,
                           const Ensemble& floor);
  /// Test k's Sigma, one member's scatter and the terms the simulator's scatter stands for (cov_, member_cov_,
  /// spread_cov_), from its features' standard deviations correlated along strain over `length`; `lab` where the
  /// test takes the lab's noise (its specimen factor moves the whole q curve), `sim_specimen` where a feature's
  /// specimen term is the simulator's scatter scaled, `data_var` the data's own noise.
  void add_test_covariance(const std::vector<Feature>& fs, Real length, const LabCurveNoise* lab,
                           const std::vector<char>& sim_specimen, const std::vector<Real>& data_var, Real sigma3);
  /// Sets each feature's `field` to sd[test][feature] and adds it to Sigma, correlated along strain.
  void add_correlated(const std::vector<std::vector<Real>>& sd, Real Feature::*field, const std::string& what);
  std::vector<std::vector<Feature>> features_;
  std::vector<std::vector<Real>> cov_;   ///< per test, Sigma (n x n, row-major)
  std::vector<std::vector<Real>> member_cov_;  ///< per test, one member's scatter (n x n): Sigma holds it / K
  /// Per test, the terms of Sigma that the simulator's scatter stands for (n x n): the specimen's where it is the
  /// simulator's (not a lab's or the replicates'), and the ensemble mean's.
  std::vector<std::vector<Real>> spread_cov_;
  SpecimenSpread specimen_spread(const Ensemble& scatter) const;
  std::vector<std::string> notes_;
  std::string source_;
  Real length_ = 1;
  int members_ = 1;
  Real sim_balls_ = 0;
  bool curves_ = true;
};

/// A part of the data the held-out check (host/fit/diagnose.hpp) predicts from the rest: residuals `local` of test
/// `test` (indices into its own residuals), at `global` in the whole residual vector.
struct HeldOutPart {
  std::size_t test = 0;
  std::vector<std::size_t> local, global;
};
/// The held-out parts of a misfit's data, and what they are in words (`basis`): each test from the others where the
/// data hold two or more; where they hold one test with a curve, its two halves by strain, each from the other (the
/// curve beyond the median strain from the curve before it, and back); none where one test has no curve to halve,
/// `basis` then saying why no held-out check can be made.
struct HeldOutParts {
  std::vector<HeldOutPart> parts;
  std::string basis;
};
HeldOutParts heldout_parts(const Misfit& misfit);

/// The noise budget decided: `lab`'s scatter specimens run at `base` on every measured test. With an "auto" ensemble
/// ([calibrate] ensemble), the lab's ensemble becomes the fewest specimens (at most all the scatter specimens) whose
/// mean's standard error is below kEnsembleRatioGoal of the data's noise. Where all of them fall short and the cell
/// is "auto" too ([calibrate] cell_factor), the cell grows by the factor that makes up the rest (at most
/// kMaxCellFactor; the mean of K specimens of N balls scatters as 1 / sqrt(K N)) and the scatter is measured again
/// on it; where `state` holds the lab's match to the data's void ratio, the grown cell is matched again
/// (PeriodicLab::grow_cell) and the budget's state says what it reaches. Then the cell's bias is measured
/// (measure_cell_bias) unless `cell_bias` is false. This is the one place that sets the lab's ensemble and cell.
NoiseBudget decide_noise_budget(PeriodicLab& lab, const Model& base, const std::vector<TriaxialTest>& measured,
                                const NoiseOptions& noise, bool cell_bias = true, const StateMatch& state = {});
/// The misfit of the budget decide_noise_budget decides.
Misfit measure_misfit(PeriodicLab& lab, const Model& base, const std::vector<TriaxialTest>& measured,
                      const NoiseOptions& noise, bool cell_bias = true, const StateMatch& state = {});

/// Fewer scatter specimens leave the covariance of their departures too uncertain to weigh (its Student's t factor
/// nu / (nu - 2) needs nu = S - 1 above 2).
constexpr int kMinSpreadSpecimens = 4;

/// The chi2 of whitened residuals: the sum of their squares, of r[from, to) where given.
Real sum_sq(const std::vector<Real>& r, std::size_t from, std::size_t to);
Real sum_sq(const std::vector<Real>& r);
/// The sum of squares of r at the indices `at`, in their order.
Real sum_sq(const std::vector<Real>& r, const std::vector<std::size_t>& at);
/// The quantile of chi2 with nu degrees of freedom at the standard normal score z (Wilson-Hilferty: within 3% of
/// the exact quantile at nu = 1, 95%, and closer as nu grows).
Real chi2_quantile(Real nu, Real z);

}  // namespace dem
