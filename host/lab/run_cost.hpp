#pragma once
/// What a cell's runs and packings cost, estimated before any runs (a job's plan, host/fit/job_plan.hpp): steps from
/// the config's rates and time step, and the engine's speed from a probe on this machine.
#include "host/config/config.hpp"

namespace dem {

/// Densest solid fraction a packing of the cell reaches (frictional spheres pack 0.58-0.64): where the gas phase of
/// a packing ends.
constexpr Real kPackedSolidFraction = 0.62;
/// A packing's steps as a multiple of its gas phase's (the cell closing at the gas phase's and then the
/// consolidation's rate to a dense state): the settling to the preparation's unbalanced tolerance takes about as many
/// again. Measured (means of 8 seeds): the 120-ball hidden-effect cell 13,640 steps against 13,910 estimated, the
/// 200-ball calibration base 17,230 against 13,260; the 1,000-ball walled cross-code base 12,800 against 19,150 (one
/// seed); an estimate, which the job's last line sets beside what it took.
constexpr Real kPackingStepsOverGas = 2.0;
/// A packing's steps at preparation friction mu over those at a typical one (0.03-0.08, the shipped configs' and the
/// cross-code data's), the range of the cells measured: with little friction the balls slide on and the unbalanced
/// force settles slowly. Measured (30 November, steps to the preparation's tolerance, each cell at its own friction =
/// 1): at mu = 0, 3.47 (periodic 1,000 balls), 3.47 and 3.55 (walled 1,000 and 4,000), 2.35 (periodic 200); at 0.0025,
/// 0.01, 0.04, 0.3 on the walled 1,000: 2.07, 1.74, 1.30, 0.86; at 1: 1.06 (walled 4,000), 1.36 (periodic 1,000), 1.48
/// (periodic 200). A state match packs both ends of [0, 1] (preparation_reach): the plan counts them so.
struct PackingCost {
  double low = 1, high = 1;
};
PackingCost packing_cost_at(Real prep_mu_s);
/// A run's steps beyond its shear, as a share of them: its consolidation to sigma3 (measured 0.04 of the shear on
/// the walled cross-code base, 0.09 in the small S-1 membrane test) and its set-up and records, which the probe does
/// not time. With 0.25 the walled case's 24 scatter and 12 check runs came within 20% of the plan (26 s and 1m10s
/// against 31 s and 1m06s).
constexpr Real kConsolidationShare = 0.25;
/// Below this sliding friction a run's consolidation settles its packing again: the balls slide on at sigma3 until
/// the unbalanced force falls to the run's tolerance (tighter than the preparation's). Measured (2 December, the
/// periodic cells' consolidation after a preparation at 0.03): the 120-ball hidden-effect cell 11,900 steps at 0.005
/// against 1,400 at 0.01 and 200 at 0.05; every cell 100-200 steps at 0.15.
constexpr Real kSlidingFriction = 0.0075;
/// Such a consolidation's steps as a multiple of the cell's packing's (packing_steps), the range measured at mu_s = 0
/// (2 December, 100 and 300 kPa, after a preparation at 0.03): the 120-ball hidden-effect cell 0.8 to 1.45 (0.56
/// after a frictionless preparation), the 200-ball calibration base 2.4 and 3.2, the 1,000-ball S-1 cell 3.5 at 300
/// kPa and 17.7 and 18.5 (two seeds) at 100 kPa: a frictionless packing is marginally rigid, and its unbalanced force
/// lingers near the tolerance for longer the larger the cell. The plan counts the whole range and says why it is wide.
struct ResettleCost {
  static constexpr Real low = 0.5, high = 20.0;
};
/// A compression test's holds (its consolidation to the seating stress and each increment, host/triax/
/// compression_test.hpp) in the cell's convergence checks ([periodic] check_every steps apart), the range of the cells
/// measured: each hold converges in 2 to 7 checks (3 December, oedometer and isotropic, sigma3 2, 4, 8, 4, 2 times 100
/// kPa: the 120-ball hidden-effect cell at emod 1e8, 1e9 and 1e10, the 200-ball calibration base and the 1,000-ball S-1
/// cell; a test's six holds 17 to 25 checks, 2.8 to 4.2 a hold). A plan counts a test's mean hold at the ends below.
struct HoldChecks {
  static constexpr Real low = 2, high = 5;
};

/// Contact pairs a ball of a random packing has (4.5, docs/performance.md) over the probe lattice's 3: the probe's
/// speed is scaled by it.
constexpr Real kPairsOverLattice = 1.5;

/// The cost of one cell's work on this machine: its balls, its time step, the engine's speed on it.
/// The largest lattice the speed probe steps: a particle-step costs about the same from 10^3 to 10^6 balls (within
/// 18%, perf/scaling.sh), while building a lattice of a million balls took the plan 65-80 s in silence.
constexpr long kMaxProbeBalls = 32768;

struct CellCost {
  long balls = 0;
  long probed_balls = 0;            ///< the lattice the speed was measured on (at most kMaxProbeBalls)
  Real dt = 0;                      ///< s, the runs' time step
  Real d = 0, rho_eff = 0;          ///< m, kg/m^3: the inertial number's scales
  double ns_per_particle_step = 0;  ///< this process's threads, as a run of the cell takes them
  long packing_steps = 0;           ///< one specimen's packing and preparation, estimated
  Real mu_s = 0;                    ///< the runs' sliding friction (the config's material)
  /// Steps of one run's shear at sigma3 (Pa): the config's end strain at its axial rate (given, or from its
  /// inertial number at p = sigma3, as resolve_periodic_params sets it).
  long shear_steps(Real sigma3) const;
  /// Steps of one run's consolidation at sigma3 (Pa), at the lower or the upper end of its range: a share of its
  /// shear, and below kSlidingFriction a packing's settling again.
  long consolidation_steps(Real sigma3, bool high = true) const;
  /// Steps of one run at sigma3 (Pa): its shear and its consolidation.
  long run_steps(Real sigma3, bool high = true) const { return shear_steps(sigma3) + consolidation_steps(sigma3, high); }
  double run_seconds(Real sigma3, bool high = true) const {
    return 1e-9 * ns_per_particle_step * balls * run_steps(sigma3, high);
  }
  /// Steps of a packing's settling again in a run's consolidation (below kSlidingFriction; else 0).
  long settling_steps(bool high = true) const;
  /// Steps of one compression test with `increments` increments: a hold each and the consolidation's (HoldChecks),
  /// and below kSlidingFriction a packing's settling again.
  long compression_steps(std::size_t increments, bool high = true) const;
  /// Whether a run's consolidation settles its packing again (mu_s below kSlidingFriction): its steps are a range.
  bool resettles() const { return mu_s < kSlidingFriction; }
  double packing_seconds() const { return 1e-9 * ns_per_particle_step * balls * packing_steps; }
  /// Runs (and packings) stepped side by side as one batch (batch_in_effect), and what each further cell of a batch
  /// adds to its time, as a share of one cell's: a batch steps all its cells in one launch per kernel, so on a GPU
  /// a cell adds a sliver (the fifth device run: 48 runs of 200 balls in 9 s where the plan, pricing one at a time,
  /// said 3m58s), on a CPU about a whole cell. The probe measures it where batch > 1.
  int batch = 1;
  double batch_growth = 1;
  /// Wall seconds of n pieces of `each` seconds: at_once side by side (forked runs), or, where batch > 1, in
  /// batches of at most `batch`, a batch of k taking each (1 + (k - 1) batch_growth).
  double seconds_of(double n, double each, int at_once) const;
  PeriodicTriaxialParams triax;     ///< the cell's test parameters
};

/// A membrane test's particle-step over a periodic cell's of the same balls: the membrane's facets, its nodes and the
/// platens. The small S-1 case at one thread (28 November): 83,450 steps of 3,662 balls in 1 min 48 s, 350 ns a
/// particle-step, against the cell probe's 150.
constexpr Real kMembraneStepOverCell = 2.3;

/// A membrane test's cost (a job's prediction, the `triaxial` command's plan): its specimen's balls, the time step
/// and speed of a cell of them, and its shear's steps as the test plans them (shear_plan) at each pressure, a
/// consolidation share more. The specimen's layers are not counted.
struct MembraneCost {
  Config cfg;
  CellCost cell;
  explicit MembraneCost(const Config& membrane);
  double steps(Real sigma3) const;
  double seconds(Real sigma3) const;
};

/// Wall seconds of n pieces of `each` seconds, at_once of them side by side.
double side_by_side_seconds(double n, double each, int at_once);

/// Runs a lab steps side by side as one batch for `batch` ([calibrate] batch; kAutoBatch: 4096 on a GPU build, 1 on
/// a CPU): 1 for a cell between walls, which CellBatch does not take (PeriodicLab::set_batch).
int batch_in_effect(long batch, const Config& cell);

/// The cost of `cell` (a periodic or walled cell config): its time step from a lattice of its balls pressed together
/// (as the runs' contacts are), the speed from stepping that lattice for about `probe_seconds` (at least 50 steps),
/// and where the lab batches its runs, a batch's growth from stepping one lattice and kGrowthProbeCells of them as
/// batches.
CellCost measure_cell_cost(const Config& cell, double probe_seconds = 0.3);

}  // namespace dem
