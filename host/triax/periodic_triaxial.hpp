#pragma once
/// Periodic-cell triaxial test: no platens, no membrane. A fully periodic cell deforms
/// homogeneously (Simulation::set_strain_rate); the axial (z) strain rate is prescribed and the lateral
/// (x, y) stresses, measured from the ball-ball contacts (Love-Weber, Simulation::contact_stress), are
/// servo-controlled to sigma3. Fast constitutive runs for calibration, like YADE's PeriTriaxController.
///
/// Stages: (a) isotropic consolidation, all three axes servoed to sigma3 until every normal stress is
/// within `stress_tolerance` of it and the unbalanced-force ratio is below `unbalanced_tolerance`;
/// (b) drained shear at a constant axial compression rate with both lateral axes servoed to sigma3.
///
/// Conventions (compression positive for stresses and strains; SI inside, units in output column names):
///   eps_a = (h0 - h) / h0        engineering axial strain (like the paper); h = cell length along z,
///                                h0 at the start of shear
///   eps_v = -(V - V0) / V0       volumetric strain, V = cell volume, V0 at the start of shear
///   sigma1 = sigma_zz (axial), sigma2 = sigma_xx, sigma3 = sigma_yy: all three measured from the contacts
///   q = sigma1 - (sigma2 + sigma3) / 2 + membrane   (measured lateral stresses, not the applied sigma3; the
///                                membrane extension's confinement is counted in q, as in a lab's sigma1 - cell)
///   p = (sigma1 + sigma2 + sigma3) / 3
///   phi_mob = asin(q / (q + 2 sigma3'))   mobilised friction angle (friction_angle_deg), sigma3' = (sigma2 + sigma3)
///                                / 2 - membrane: the confinement q is measured from
///   I = axial_rate d sqrt(rho_eff / p)   inertial number, d = mean diameter, rho_eff = density x mass_scale
/// Axial kinematics: the cell's axial velocity gradient is constant (-axial_rate, a constant true strain
/// rate, as YADE's goal strain rate), so eps_a = 1 - exp(-axial_rate t) and I stays constant at fixed p.
///
/// Lateral servo (PFC-style gain from the contact stiffness and the time step), applied every step:
///   rate_i = gain_i (sigma_ii - sigma3) / sigma3,  gain_i = alpha sigma3 / (K_ii dt),  |rate_i| <= max rate,
///   K_ii = (1/V) sum_c kn_c l_ci^2,   kn_c = Fn_c / overlap_c (secant normal stiffness of each contact).
/// K_ii bounds the affine stiffness d sigma_ii / d eps_ii = (1/V) sum_c l_ci^2 (kn n_i^2 + ks (1 - n_i^2))
/// from above when ks <= kn (kn/ks >= 1, the paper's 1.5), so one step of the affine response corrects at
/// most the fraction alpha of the stress error: for alpha <= 1 the discrete loop e <- (1 - alpha K/K_ii) e
/// is stable and monotone, and the non-affine relaxation of the particles only lowers the real stiffness.
/// A positive rate extends the cell (stress too high -> extend).
#include <array>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "host/config/config.hpp"
#include "host/engine/builder.hpp"
#include "host/io/io_hdf5.hpp"
#include "host/engine/simulation.hpp"
#include "host/engine/stage_loop.hpp"

namespace dem {

// PeriodicTriaxialParams and the [periodic] table (PeriodicConfig) are in config.hpp.

/// One row of the shear series (SI; stresses in Pa, strains as fractions).
struct PeriodicTriaxialRecord {
  long step = 0;
  Real time = 0;                     ///< s since the start of the simulation
  Real eps_a = 0, eps_v = 0;
  Real sigma1 = 0, sigma2 = 0, sigma3 = 0;  ///< zz, xx, yy from the contacts
  Real q = 0, p = 0, phi_mob_deg = 0;
  /// Pa, q over the cross-section at the start of shear (L_x L_y there): the deviator force over a fixed area, as a
  /// lab that does not correct its area reports it (q_measure fixed_area); q is over the current cross-section.
  Real q_fixed_area = 0;
  Real void_ratio = 0;               ///< V / V_solid - 1
  Real coordination = 0;             ///< 2 x touching ball-ball contacts / balls (rattlers included)
  Real unbalanced = 0, kinetic = 0;  ///< unbalanced-force ratio, fluctuating kinetic energy (J)
  Real inertial = 0;                 ///< axial_rate d sqrt(rho_eff / p) at this row's p
  Real rate_x = 0, rate_y = 0;       ///< servoed lateral strain rates (1/s, extension positive)
  Real membrane = 0;                 ///< Pa, mean lateral confinement of the membrane extension (in sigma2/3, not q)
};

struct PeriodicTriaxialResult {
  PeriodicTriaxialParams params;     ///< with the automatic values filled in
  long consolidation_steps = 0;
  Real mean_diameter = 0, density_eff = 0;   ///< m, kg/m^3 (density x mass_scale)
  Real inertial = 0;                 ///< I of the axial rate at p = sigma3
  Real h0 = 0, V0 = 0, void_ratio0 = 0;      ///< cell at the start of shear
  std::vector<PeriodicTriaxialRecord> series;
  /// Summarised like measured curves (summarised, host/data/measured.hpp): the peak of the moving mean of q, q_end
  /// the mean over the last 1% of strain, the dilatancy over 0.5% windows.
  Real q_peak = 0, eps_a_peak = 0, phi_peak_deg = 0, q_end = 0, max_dilatancy = 0;
  Real max_lateral_error = 0;        ///< max over rows of |sigma2 or sigma3 - applied| / applied
  Real max_kinetic = 0;              ///< J, over rows
  double wall_seconds = 0;
  std::vector<StageTiming> stages;   ///< consolidation and shear
};

/// Steps of a shear to the engineering axial strain `target_strain` at the constant true strain `axial_rate` (1/s)
/// with time step dt (s): the stage's plan, and a job's estimate of its cost (host/lab/run_cost.hpp).
inline long shear_step_count(Real target_strain, Real axial_rate, Real dt) {
  return static_cast<long>(std::ceil(-std::log(1 - target_strain) / (axial_rate * dt)));
}

/// Fills in the automatic rates and checks the parameters against the simulation: fully periodic, no
/// walls, zero gravity, I within bounds. Throws std::invalid_argument with the reason.
PeriodicTriaxialParams resolve_periodic_params(Simulation& sim, PeriodicTriaxialParams prm);

/// Stage (a) alone: all three axes servoed to sigma3 (rates clamped to consolidation_rate). Returns the steps
/// taken; throws std::runtime_error naming the stresses and unbalanced ratio reached when
/// max_consolidation_steps pass without convergence, std::invalid_argument as resolve_periodic_params.
StageEnd consolidate_isotropic(Simulation& sim, const PeriodicTriaxialParams& prm);

/// Stages (a) and (b). With `out`, writes series.csv/.h5 and the snapshots at snapshot_strains.
PeriodicTriaxialResult run_periodic_triaxial(Simulation& sim, const PeriodicTriaxialParams& prm,
                                             io::Output* out = nullptr);

/// One specimen's outcome in a batch (run_periodic_batch): its result as run_periodic_triaxial gives it, its
/// consolidation's end as consolidate_isotropic gives it, or why it stopped: a blow-up (the BlowUp's message), or a
/// consolidation that did not converge (the std::runtime_error's message).
struct BatchedTest {
  PeriodicTriaxialResult result;
  StageEnd consolidation;
  std::string blowup, failure;
  /// With consolidate_only, the balls (by gid in the specimen's Simulation) and the cell at the stage's end.
  HostParticles balls;
  Domain domain;
};

/// The periodic test of each specimen, side by side in one CellBatch (host/engine/cell_batch.hpp): stage (a), and
/// unless consolidate_only stage (b), each specimen with its own parameters. Each outcome is bit for bit that of
/// the specimen's own run (consolidate_isotropic, run_periodic_triaxial), without output or progress lines; a
/// specimen that blows up or fails to converge stops and the others go on. The Simulations must be fresh (as
/// CellBatch takes them) and are not stepped.
/// `steps` receives the batch's steps and those of them with a rebuild (CellBatch::rebuild_steps).
std::vector<BatchedTest> run_periodic_batch(const std::vector<Simulation*>& sims,
                                            const std::vector<PeriodicTriaxialParams>& prms,
                                            bool consolidate_only = false, std::array<long, 2>* steps = nullptr);

/// "a periodic cell" or "a cuboid between six walls", for messages.
const char* cell_name(CellBoundary b);

/// A simulation of `balls` in [0, cell) with one contact law for every pair of balls and no gravity: fully
/// periodic, or between the six walls of cell_walls (host/triax/cell_boundary.hpp), frictionless and otherwise of the
/// balls' law; the solver settings (damping, dt, mass scale, skin in mean diameters) from `solver`.
std::unique_ptr<Simulation> make_periodic_simulation(const std::vector<BallSpec>& balls,
                                                     const std::array<Real, 3>& cell, const ContactParams& law,
                                                     const SolverConfig& solver,
                                                     CellBoundary boundary = CellBoundary::periodic);

/// The balls' current state in gid order (positions wrapped into the cell, or taken from the walled cell's
/// lower corner, velocities kept), to rebuild a specimen with another contact law or numbering. `cell` receives
/// the cell lengths.
std::vector<BallSpec> extract_balls(Simulation& sim, std::array<Real, 3>& cell);


/// Refuses a config that is not a cell without gravity: fully periodic, or with [periodic] boundary = "walls"
/// (whose [box] is then the cuboid the balls are inserted into, periodic or not).
void check_periodic_config(const Config& cfg);

/// The specimen of a periodic job: the packing of [particles]/[box], consolidated to [periodic] sigma3_kPa
/// with the preparation friction (prep_mu_s, prep_mu_r) when that differs from the material's, without the
/// model extensions. `balls` and `cell` receive it; returns the preparation's steps (0 where there was none).
/// `keep`, where given, holds the preparation's simulation, so that a blow-up's state can be saved for inspection.
long prepare_periodic_specimen(const Config& cfg, std::vector<BallSpec>& balls, std::array<Real, 3>& cell,
                               bool verbose, std::unique_ptr<Simulation>* keep = nullptr);

/// A specimen prepared: its balls in their cell.
struct PreparedCell {
  std::vector<BallSpec> balls;
  std::array<Real, 3> cell{};
};
/// The specimens of several configs (seeds), their preparations side by side in one batch (run_periodic_batch):
/// each bit for bit what prepare_periodic_specimen gives it. Throws the first specimen's error (in their order), as
/// one at a time would. Without progress lines.
std::vector<PreparedCell> prepare_periodic_specimens(const std::vector<Config>& cfgs);

}  // namespace dem
