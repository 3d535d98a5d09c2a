#pragma once
/// Calibration against measured triaxial data. The simulator, PeriodicLab, is in periodic_lab.cpp.
///
/// The simulator is the periodic-cell triaxial test (host/triax/periodic_triaxial.hpp) on one specimen prepared once
/// from the base config, so that every run differs from the others only by its parameters (common random
/// numbers: the response is then a smooth function of the parameters, up to the chaos of a small cell).
///
/// Each test (material, sigma3) is reduced to seven quantities, the same for measured and simulated curves
/// (summarise in host/data/measured.hpp): initial stiffness E_ini, q at 1% and at 3% axial strain (the shape of
/// the hardening: an effect that grows or fades with strain shows there), q_peak, eps_a at the peak, q at the
/// end, maximum dilatancy. A summary file gives those it has. The misfit is a chi-square with a lab-like noise
/// per quantity:
///   chi2 = sum over tests and present quantities of ((simulated - measured) / s_q)^2,
///   s_q = max(rel_q |measured|, abs_q)   (NoiseModel: E_ini 10%, q at 1% and 3% 6%, q_peak 4%, eps_a at
///                                         peak 2% strain, q_end 5%, dilatancy 20% or 0.05)
/// so a model that is right to within the noise has chi2 about the number of data. The levels are a lab's
/// specimen-to-specimen scatter (2-3% on strength) plus the scatter of a 200-ball cell, whose broad peak
/// moves by a few % of strain with a small change of parameters.
///
/// Search (for d free parameters, each mapped to [0, 1], linearly or logarithmically):
///   1. a 3^d factorial design (every test of the material at every point);
///   2. a quadratic response surface per datum (Eigen least squares on the normalised residuals), minimised
///      by a dense grid and then coordinate refinement;
///   3. a run at the surrogate's optimum, added to the design; the surface is refitted with weights that
///      favour points near the optimum; repeated until the run's chi2 stops improving (at most `rounds`);
///   4. a compass stage on the simulator itself: from the best run, steps of 1/4 and then 1/8 of each unit
///      range along every axis, moving to any better run. A quadratic surface cannot follow a misfit that
///      saturates or has a second, narrower valley between the design's points, and stops at an edge of the range
///      when the optimum lies inside (seen on another code's data: chi2 76 at the edge, 37 inside). 1/8 is
///      the finest step worth a run: below it the runs of a small ensemble differ by their chaos more than by
///      the step. A last surrogate round, centred on the compass's best, refines between its points;
///   5. when the best point lies on the edge of a range that can move (not a hard limit such as mu_r = 0), the
///      range is re-centred on it and the search starts again (at most `widen` times); the better answer wins.
/// The reported fit is the best point actually run, never a surrogate value.
///
/// What a search spends its runs on (Table 6's S-1, 28 November: 55 points of 12 runs where 22 were planned):
///   - a move counts only when it lowers the chi2 by a significant gain (significant_gain): the compass moves, and a
///     best point on an edge widens the range, only on such a gain over the best point inside. On a flat valley
///     floor smaller gains are the small cell's chaos (S-1: 1.800, 1.787, 1.765, 1.743, 1.701 along mu_r), and
///     following them carried the search two ranges further, 24 points, for a chi2 0.1 lower;
///   - screening (successive halving on the specimens, Jamieson & Talwalkar 2016): a point after the first runs on
///     one member of the ensemble first (with as many of the next member's tests as fill the workers' round), and
///     the others only where that member's chi2 could lie within the joint 95% region of the best so far
///     (clearly_above). Most of a 3^d design's corners and of the compass's 1/4 steps
///     lie tens of chi2 above it (S-1: 68-678 against 1.8); they keep that member's residuals, which the response
///     surfaces weigh little so far from the best. The design runs its centre first, so that the bound is known
///     early.
/// A widened search takes the best chi2 of the search before as its bound.
#include <array>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "host/config/config.hpp"
#include "host/engine/builder.hpp"
#include "host/data/measured.hpp"
#include "host/fit/misfit.hpp"
#include "host/lab/periodic_lab.hpp"

namespace dem {

/// A parameter that calibration may vary: its config key, its range, log or linear search.
struct FreeParam {
  std::string name;
  Real lo = 0, hi = 1;
  bool log = false;
  Real value(Real u) const;   ///< u in [0, 1] to the parameter
  Real unit(Real v) const;    ///< the inverse
  Real shown = 1;             ///< factor from SI to the config key's unit (1e-3 for membrane_kPa)
};

/// A parameter triaxdem can free (host/config/model_keys.hpp: its key and default search range; membrane_kPa in
/// Pa inside). Throws std::invalid_argument naming the allowed names.
FreeParam free_param(const std::string& name);
/// The same, centred on the base model's value where that is set: mu_s and emod_Pa over a factor 3
/// either way (log), mu_r over [0, max(4 x value, 0.05)]. A 3 x 3 design then lands near a sensible answer.
FreeParam free_param(const std::string& name, const Model& base);
void set_param(Model& m, const std::string& name, Real v);
/// True for a parameter of the contact law (every test has it); false for the periodic cell's membrane extension.
bool is_contact_param(const std::string& name);
Real get_param(const Model& m, const std::string& name);

/// A quadratic response surface in unit coordinates: value(u) = c . basis(u), fitted by weighted least squares.
class QuadraticSurface {
 public:
  QuadraticSurface() = default;
  QuadraticSurface(const std::vector<std::vector<Real>>& u, const std::vector<Real>& y, const std::vector<Real>& w);
  Real operator()(const std::vector<Real>& u) const;
  static std::vector<Real> basis(const std::vector<Real>& u);

 private:
  std::vector<Real> c_;
};

/// One evaluated point of a search.
struct Evaluation {
  std::vector<Real> u;                ///< unit coordinates of the free parameters
  std::vector<TriaxialTest> sim;      ///< simulated tests: the mean curves of the ensemble (mean_curve)
  std::vector<Real> r;                ///< normalised residuals (all tests)
  Real chi2 = 0;
  bool screened = false;              ///< run on one member only (sim and r are that member's): clearly worse
  int specimen = -1;                  ///< one specimen a point: the specimen it ran on; -1: the ensemble's mean
};

struct CalibrationResult {
  Model model;                        ///< base model with the calibrated values
  /// The ranges searched: after a widened search, their union (every point's u is in it), so that the intervals and
  /// the region reach over every range a search ran.
  std::vector<FreeParam> free;
  std::vector<Real> values;
  Evaluation best;                    ///< the best point run
  std::vector<Evaluation> design;     ///< every point run, in order (a widened search's after its first search's)
  int data = 0;                       ///< number of data in the misfit
  /// Names of the parameters whose best value lies on an edge of its range (within 1% of it): the true
  /// optimum may lie outside, and a misfit found there may be the range's and not the model's. A lower edge
  /// at zero is not one: nothing lies below it (no rolling resistance, no wear).
  std::vector<std::string> at_edge() const;
  /// What the search did to ranges whose best value fell on an edge ("mu_s range moved to [0.15, 1.35]").
  std::vector<std::string> widened;
  /// Parameters searched beyond the edge their best value lies on, without a better point there: the
  /// optimum is at the edge within the scatter of the runs, and at_edge() does not flag them.
  std::vector<std::string> searched_beyond;

  /// Uncertainty, from the response surfaces of the residuals around the best run (the surrogate chi2, shifted
  /// to agree with that run): each parameter's 95% profile interval (where the chi2 minimised over the others
  /// rises by 3.84 x scale), the correlation of the free parameters (Gauss-Newton, (J^T J)^-1), and the joint
  /// 95% region (a rise of the chi2 quantile with d degrees of freedom). scale = chi2 / (n - d) where that
  /// exceeds 1: a misfit beyond the noise widens the region by its root, as the noise was understated.
  ///
  /// Measured on the specimens (where `spreads` holds the scatter specimens' departures, Misfit::specimen_spreads):
  /// the answer's covariance is the sandwich G (I - M + M_s) G^T, G = (J^T J)^-1 J^T the Gauss-Newton map from
  /// whitened residuals to unit coordinates, M the misfit's modelled specimen and ensemble terms, M_s the specimens'
  /// sample covariance of the same terms (times nu / (nu - 2), nu = S - 1, as the misfit counts an estimated
  /// variance): the data specimen's term within each test (a specimen a test), the ensemble mean's across tests too
  /// (its members are the same packings at every pressure). Each profile's rise is then 3.84 x scale x rise_factor[j], rise_factor[j] the sandwich's variance of
  /// parameter j over (J^T J)^-1's; the joint region's chi2_95(d) x scale x region_factor, region_factor the 95%
  /// quantile of sum lambda_i z_i^2 (lambda the eigenvalues of J^T J times the sandwich; Satterthwaite's scaled
  /// chi2) over chi2's with d degrees of freedom. With several spreads (the base model's specimens and the
  /// calibrated point's) each factor is the larger. On the program's synthetic data one 120-ball specimen's
  /// departure crosses q and eps_v and turns along strain as the modelled terms do not: the truth's run lay 20-40
  /// above the best chi2 where the modelled region's rise was 6 (docs/calibration.md, Coverage).
  std::vector<std::pair<Real, Real>> interval;     ///< SI, per free parameter
  std::vector<std::vector<Real>> correlation;      ///< d x d
  Real scale = 1;
  std::vector<SpecimenSpread> spreads;             ///< empty: the misfit's model alone
  std::vector<Real> rise_factor;                   ///< per free parameter; 1 without spreads
  Real region_factor = 1;
  /// The surrogate chi2 at unit coordinates u.
  Real surrogate_chi2(const std::vector<Real>& u) const;
  /// How far parameter values (SI, in free order) lie from the best, as the surrogate chi2's rise over the
  /// joint 95% region's: at most 1 inside the region; infinite outside the searched ranges.
  Real region_rise(const std::vector<Real>& values) const;
  /// Pairs of parameters whose correlation is beyond +-0.9, in words ("mu_s and mu_r (-0.95)"): these data
  /// cannot separate them.
  std::vector<std::string> inseparable() const;
  /// How flat the minimum is: the share of the searched box (unit coordinates, a grid) where the surrogate chi2
  /// lies within the joint 95% rise of the best. A few % is a sharp optimum; tens of % say the data hardly
  /// constrain the parameters over their ranges.
  Real flat_share() const;
  std::vector<QuadraticSurface> surfaces;          ///< the residuals' surfaces around the best run
  std::vector<Real> offset;                        ///< best-run residual minus surface value there
  /// One specimen a point (OneSpecimenSearch): the answer is the surfaces' minimum, its residuals and chi2 the
  /// surfaces' there (no offset), since every run carries its one specimen's scatter and the surfaces average it over
  /// the design; the best run means nothing.
  bool surrogate_answer = false;
  /// The ensemble the surfaces' value at the answer is worth: 1 / sum over specimens of the square of their share of
  /// it (the surfaces' weights of each point summed over the points a specimen ran, as one specimen's departure moves
  /// every run of it alike), or 1 / sum of the points' squared weights where that is larger (departures that change
  /// from point to point). The misfit whitening the answer counts the simulator's scatter as that of this ensemble's
  /// mean. At most the number of specimens; 0 where no point ran on one specimen.
  Real surrogate_members() const;
};

/// Moves f's range to centre on v, keeping its width (its ratio when logarithmic), inside the registry's range
/// for the name (free_param(name)); false when it cannot move (v on a hard limit, such as mu_r = 0).
bool recentre(FreeParam& f, Real v);

/// Called after each run with (runs done, runs planned, best chi2 so far).
using CalibrationProgress = std::function<void(long, long, Real)>;

/// What a search asks of its simulator at one model: the simulated tests and the normalised residuals.
struct SimulatedPoint {
  std::vector<TriaxialTest> sim;
  std::vector<Real> r;
  bool screened = false;  ///< run on part of the ensemble, clearly above the bound the search gave
  int specimen = -1;      ///< one specimen a point: the specimen it ran on
};
/// The simulator at a model, given a chi2 bound (`screen_above`) above which the point matters to the search only as
/// worse than its best: the simulator may then run it on part of its ensemble and return that part's estimate, where
/// that lies clearly above (infinity: run it whole). kProbe asks for the part alone, screened, as a probe: a later
/// call at the same model goes on from it (a simulator without parts returns the whole point, not screened).
using Simulator = std::function<SimulatedPoint(const Model& m, Real screen_above)>;
inline constexpr Real kProbe = -std::numeric_limits<Real>::infinity();

/// The 95% quantile of chi2 with d degrees of freedom: the table's for d = 1..4, where Wilson-Hilferty is up to 3%
/// low, chi2_quantile beyond.
Real chi2_95(int d);
/// The least fall of the chi2 that a search counts as a better point: a twentieth of the joint 95% region's rise
/// (chi2_95(d) x scale, scale = max(1, chi2 / (data - d)), as the intervals count it). Such a gain moves the
/// optimum by about a fifth (the root of 1/20) of the region's radius, within the region's own uncertainty.
Real significant_gain(Real best_chi2, int data, int d);
/// The bound a search screens against: the best chi2 so far plus the joint 95% region's rise, the points that
/// shape the intervals.
Real screen_bound(Real best_chi2, int data, int d);
/// Whether residuals `r` of one member lie clearly above a chi2 `bound` for the ensemble's mean: their norm less
/// kScreenSigmas times the root of `spread` (Misfit::member_spread, the expected square norm of one member's
/// departure from the mean) still exceeds the bound's root (the triangle inequality; a departure beyond 2.5 roots of
/// its expected square norm has a chance of at most 1.2%, for one datum, and less for more).
bool clearly_above(const std::vector<Real>& r, Real spread, Real bound);
constexpr Real kScreenSigmas = 2.5;

/// One specimen a point (CalibrateConfig::method "one_specimen"): instead of an ensemble's mean at every point, each
/// point runs every test on one specimen, taken in turn from the scatter specimens (the same list at every point), and
/// the surfaces carry the specimens' scatter: a quadratic surface fitted to many points averages their specimens'
/// departures as an ensemble does at one point (stochastic kriging's idea with a quadratic trend). The search:
///   1. the scatter runs at the base model, one point a specimen, and the 3^d design, each point on the next specimen;
///   2. rounds: the surfaces' minimum is run on the next specimen, until it and the joint 95% region's half-widths
///      (Gauss-Newton's) move by less than a tenth of those half-widths between two rounds, or `rounds` are run;
///   3. the answer is the surfaces' minimum (CalibrationResult::surrogate_answer); a minimum on an edge of a range that
///      can move searches again beyond it (at most `widen` times), as the ensemble's search does.
/// The misfit it searches with whitens one run (an ensemble of 1); the job whitens the design again at the answer with
/// the ensemble the surfaces are worth there (CalibrationResult::surrogate_members, rescattered).
struct OneSpecimenSearch {
  std::vector<SimulatedPoint> at_base;  ///< the scatter runs at the base model, one a specimen: design points there
  int rounds = 6;
};

/// Calibrates `free` from `base` on a misfit of `data` data; see the top of the file.
CalibrationResult calibrate(const Simulator& simulate, const Model& base, const std::vector<FreeParam>& free, int data,
                            int rounds = 4, int widen = 2);
/// One specimen a point (OneSpecimenSearch) on a simulator that runs each point on one specimen.
CalibrationResult calibrate(const Simulator& simulate, const Model& base, const std::vector<FreeParam>& free, int data,
                            const OneSpecimenSearch& one, int widen = 2);
/// The same on `measured`, simulated by the lab: point i (the scatter runs' points at the base first) on specimen
/// i mod the lab's specimens, whitened by `misfit` (an ensemble of 1: one run's scatter).
CalibrationResult calibrate_one_specimen(PeriodicLab& lab, const Model& base, const std::vector<FreeParam>& free,
                                         const std::vector<TriaxialTest>& measured, const Misfit& misfit,
                                         const CalibrationProgress& progress = {}, int widen = 2);
/// Points a one-specimen search of d free parameters runs at most before any widening, besides its points at the base.
long planned_one_specimen_points(int d, int rounds = OneSpecimenSearch{}.rounds);
/// Residuals of other tests than the triaxial ones, fitted with them (host/fit/compression_misfit.hpp): `data` of them
/// at a model, appended to the triaxial residuals at every point. Empty: none.
struct JointTerm {
  int data = 0;
  std::function<std::vector<Real>(const Model&)> residuals;
  /// The triaxial residuals `r` of a run at m with the joint tests' at m after them: the order every fit's chi2,
  /// surfaces and data count assume.
  std::vector<Real> appended(const Model& m, std::vector<Real> r) const {
    if (!residuals) return r;
    const std::vector<Real> more = residuals(m);
    r.insert(r.end(), more.begin(), more.end());
    return r;
  }
};
/// The same on `measured` (one material, any number of pressures), simulated by the lab's ensemble, with `joint`'s
/// tests fitted beside them.
CalibrationResult calibrate(PeriodicLab& lab, const Model& base, const std::vector<FreeParam>& free,
                            const std::vector<TriaxialTest>& measured, const Misfit& misfit, int rounds = 4,
                            const CalibrationProgress& progress = {}, int widen = 2, const JointTerm& joint = {});
/// A run of the base model found after the calibration (a nested model's run at strength 0) that beats its best:
/// it joins the design and becomes the best, and the values, the model (`base` with them) and the uncertainty are
/// computed again at it, so that the intervals and correlation belong to the reported point.
void adopt_best(CalibrationResult& r, const Evaluation& better, const Model& base);

/// The misfit measured again at the calibrated point (Misfit::with_scatter): every point of the design whitened again by
/// `misfit` from its
/// simulated curves (its ensemble's mean; a screened point's one member), the best point chosen again among those run
/// whole, and the values, model and uncertainty computed at it. The simulator's scatter grows with the friction (the
/// hidden-effect cell at mu_s 0.37, mu_r 0.05: q's standard deviation 1.5-3 times the base model's 0.15, 0.015 from
/// 0.5% strain): measured at the base model alone it understated the noise at a calibrated point far from it, and the
/// intervals missed the parameters that made synthetic data; at the calibrated point alone it understated it where
/// the truth lies back toward the base (docs/calibration.md, Coverage).
/// The intervals and region of r measured on `spreads` (CalibrationResult; empty: the misfit's model alone), at its
/// best point.
void measure_on_specimens(CalibrationResult& r, std::vector<SpecimenSpread> spreads);
/// The spreads of `misfit` (Misfit::specimen_spreads) are kept in r, so that its intervals and region are measured
/// on the specimens. A joint fit's residuals beyond the misfit's data (JointTerm: other tests') stay as they were, and
/// its intervals then rest on the misfit's model alone (the spreads cover the triaxial tests only).
void rewhiten(CalibrationResult& r, const Misfit& misfit, const Model& base);

/// r's intervals, correlation, region and surfaces at its best point, measured on r.spreads where given
/// (calibration_uncertainty.cpp).
void add_uncertainty(CalibrationResult& r);

/// Parameter points a calibration of d free parameters runs at most before any widening: the design, the
/// surrogate rounds and the compass stage (for a progress bar's plan).
long planned_points(int d, int rounds = 4);

/// One response surface per residual of the evaluations, weighted towards `centre` (unit coordinates).
std::vector<QuadraticSurface> response_surfaces(const std::vector<Evaluation>& pts, const std::vector<Real>& centre);
/// The map from the points' values to a surface's coefficients (basis x points, row-major by basis term): the weighted
/// least squares of response_surfaces centred on `centre`, the same for every residual.
std::vector<std::vector<Real>> surface_projection(const std::vector<Evaluation>& pts, const std::vector<Real>& centre);
/// What each point weighs in the surfaces' value at u (response_surfaces centred on `centre`): the row of the
/// weighted least squares' hat matrix, so that a surface's value at u is sum_i a_i y_i (the a_i sum to 1).
std::vector<Real> surface_shares(const std::vector<Evaluation>& pts, const std::vector<Real>& centre,
                                 const std::vector<Real>& u);
/// The joint 95% region's half-widths in unit coordinates at u, to first order (Gauss-Newton on the surfaces' Jacobian
/// there, a rise of `rise` in chi2); 1 along a direction the surfaces leave flat.
std::vector<Real> region_half_widths(const std::vector<QuadraticSurface>& surfaces, const std::vector<Real>& u,
                                     Real rise);

/// Calls f(u) at every point of the grid of n points per axis over the unit box [0, 1]^d, the first axis fastest.
void for_each_grid_point(int d, int n, const std::function<void(const std::vector<Real>&)>& f);

/// Minimises f over [0, 1]^d: a grid of `per_axis` points per axis (fewer for d > 3), then coordinate steps
/// that halve down to 1e-4.
std::vector<Real> minimise_unit_box(const std::function<Real(const std::vector<Real>&)>& f, int d, int per_axis = 21);

}  // namespace dem
