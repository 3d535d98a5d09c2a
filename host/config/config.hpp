#pragma once
/// Run configuration: TOML (toml++) read into plain structs. SI inside; the file speaks the units
/// researchers use (mm, kPa, kg/m^3), named in each key. Unknown keys, wrong types and values out of
/// range are refused with the file, the key and the allowed range.
#include <array>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "kernels/core/contact_params.hpp"

namespace dem {

/// A config error: what() reads "<file>: [table] key: problem (allowed: range)".
struct ConfigError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct RunConfig {
  std::string name = "run";
  std::string material;          ///< the lab material the run stands for (e.g. "S-1"): `study --compare` matches it
  long steps = 20000;            ///< time steps of the run
  std::string output = "out";    ///< output folder
  long series_every = 100;       ///< steps between time-series rows
  long snapshot_every = 5000;    ///< steps between particle snapshots (0 = first and last only)
  unsigned seed = 1;             ///< random generator seed (packing)
  Real stop_ratio = 0;           ///< stop early once the unbalanced-force ratio is below this (0 = never)
  long checkpoint_every = 0;     ///< steps between checkpoints (0 = by time only)
  Real checkpoint_minutes = 10;  ///< wall-clock minutes between checkpoints (0 = by steps only)
};

/// How the balls' diameters are distributed (host/config/size_distribution.hpp draws them): uniform by number
/// between the smallest and the largest, lognormal by mass, or a sieve table (percent passing by mass), the last two
/// as labs measure a material.
enum class SizeLaw { uniform, lognormal, sieve };

struct ParticleConfig {
  long count = 2000;
  /// m (file: diameter_mm): the mean diameter by number; of a lognormal or sieve distribution, worked out from it
  /// (the file then gives none).
  Real diameter = 2e-3;
  Real diameter_ratio = 1.0;     ///< uniform: largest / smallest diameter, uniform in between
  Real density = 2500;           ///< kg/m^3
  SizeLaw psd = SizeLaw::uniform;  ///< file: psd = "uniform", "lognormal" or "sieve"
  Real median = 0;               ///< m, lognormal: the median diameter by mass, D50 (file: median_mm)
  Real log_sd = 0;               ///< lognormal: the standard deviation of ln(d) by mass
  std::vector<Real> sieve;       ///< m, sieve: the sieve sizes, increasing (file: sieve_mm)
  std::vector<Real> passing;     ///< sieve: the fraction by mass finer than each sieve, 0 to 1 (file: passing_pct)
};

/// Box holding the particles at the start; its non-periodic faces carry plane walls when `walls`.
struct BoxConfig {
  std::array<Real, 3> size{0.03, 0.03, 0.06};  ///< m (file: size_mm)
  std::array<bool, 3> periodic{false, false, false};
  bool walls = true;
  std::string fill = "random";   ///< "random" (sequential insertion) or "lattice" (jittered cubic)
  Real lattice_spacing = 1.0;    ///< lattice pitch / largest diameter (< 1 presses neighbours together)
};

/// The most steps between the host's reads of the step statistics: the ring of steps on the device holds this many
/// (host/engine/step_rows.hpp).
constexpr long kMaxStatsEvery = 64;

struct SolverConfig {
  Real damping = 0.7;                       ///< local damping alpha
  std::array<Real, 3> gravity{0, 0, -9.81}; ///< m/s^2
  Real dt_safety = 0.2;                     ///< dt = dt_safety * critical dt
  Real dt = 0;                              ///< s; > 0 overrides dt_safety
  Real mass_scale = 1;                      ///< density scaling (quasi-static runs only)
  Real skin = 0.2;                          ///< Verlet skin / mean diameter
  Real overlap_limit = 0.1;                 ///< blow-up threshold: overlap / radius
  /// Steps between the host's reads of the step statistics (SimParams::stats_every); 0: 1 on a CPU build, where a
  /// read costs nothing, and 16 on a GPU build, where each one holds the host.
  long stats_every = 0;
};

/// Cylindrical specimen built by multilayer compaction (Tang et al. 2025, Sec. 3.3).
struct SpecimenConfig {
  Real diameter = 61.8e-3;       ///< m (file: diameter_mm)
  Real height = 120e-3;          ///< m (file: height_mm)
  Real void_ratio = 0.61;        ///< target e of the whole specimen; sets the ball count
  long ball_count = 0;           ///< > 0: this many balls instead (the target e then follows from it)
  long layers = 5;
  Real compaction_mu_s = 0.0;    ///< ball-ball friction while compacting (denser packings need little)
  Real settle_mu_s = -1;         ///< >= 0: ball-ball friction once a layer is pressed, while it settles
  Real platen_speed = 0.05;      ///< m/s, top platen speed while compacting a layer (file: platen_speed_mm_s)
  Real stop_ratio = 1e-3;        ///< unbalanced-force ratio that ends a layer
  /// > 0: the ratio that ends the layers below the top one, which the next layers press on again (the top one
  /// still ends at stop_ratio); 0: every layer ends at stop_ratio (the paper's protocol).
  Real layer_stop_ratio = 0;
  long max_steps_per_layer = 200000;
  /// A layer that reaches max_steps_per_layer before stop_ratio is not at rest: the specimen is refused (and
  /// cached, so that a rerun that accepts it starts at once) unless this is set.
  bool accept_unsettled = false;
};

/// Drained triaxial test on the [specimen]: membrane, isotropic consolidation, shear (Sec. 3.3).
struct TriaxialConfig {
  Real sigma3 = 100e3;            ///< Pa, cell pressure (file: sigma3_kPa)
  Real axial_strain_end = 0.15;   ///< (file: axial_strain_end_pct)
  Real inertial_number = 1e-3;    ///< shear rate from I = eps_dot d sqrt(rho / sigma3)
  Real record_every = 0.001;      ///< axial strain between records (file: record_every_pct)
  Real consolidation_tol = 0.005; ///< relative stress error that ends consolidation
  Real stop_ratio = 1e-3;         ///< unbalanced-force ratio that ends consolidation
  long max_consolidation_steps = 400000;
  int membrane_around = 81;       ///< nodes around
  int membrane_segments = 20;     ///< segments in height
  Real membrane_modulus = 1.4e6;  ///< Pa (file: membrane_modulus_MPa; latex)
  Real membrane_poisson = 0.49;
  Real membrane_thickness = 0.5e-3;  ///< m (file: membrane_thickness_mm)
  Real membrane_density = 930;    ///< kg/m^3
  /// Local damping during shear about the platens' axial flow (v_z = v_top z / h) instead of the absolute
  /// velocity; false is PFC's (and the paper's) way, whose drag the top platen reads (docs/performance.md, The
  /// triaxial test).
  bool damping_about_flow = false;
};

/// Micromechanics recorded during a triaxial test ([micro] table; host/triax/micro_report.hpp).
struct MicroConfig {
  bool enabled = true;
  Real rve_edge = 20e-3;   ///< m, edge of the central cube (the paper's 20 mm; file: rve_edge_mm)
  int rose_bins = 18;      ///< angle bins of the directional distributions over 0-180 deg
  /// Whether a shear record's host work (micromechanics, envelope) is worked out on a host thread beside the next
  /// steps: "on", "off", or "auto" (on where the steps run on a device; host/triax/record_work.hpp).
  std::string overlap = "auto";
};

/// The gas phase's clamp over the consolidation's where [periodic] gas_rate_per_s is automatic (see gas_rate).
inline constexpr Real kGasRateFactor = 4;
/// The highest solid fraction a gas phase may close to: below random loose packing (0.53-0.55, frictional spheres).
inline constexpr Real kGasSolidFractionMax = 0.53;

/// Periodic-cell triaxial test parameters (SI); see host/triax/periodic_triaxial.hpp for the method.
struct PeriodicTriaxialParams {
  std::string name = "periodic";     ///< label of the progress line
  Real sigma3 = 100e3;               ///< Pa, confining stress (all axes in consolidation, lateral in shear)
  Real axial_rate = 0;               ///< 1/s, compression positive (the cell shortens along z); 0: from target_inertial
  Real target_inertial = 5e-4;       ///< I at p = sigma3 that sets axial_rate when it is 0
  Real max_inertial = 1e-3;          ///< refuse an axial_rate whose I at p = sigma3 is above this ...
  bool allow_high_inertial = false;  ///< ... unless this is set (the run is then labelled not quasi-static)
  Real target_strain = 0.15;         ///< engineering axial strain at the end of shear
  Real servo_alpha = 0.5;            ///< fraction of the stress error one step of affine response corrects, (0, 1]
  Real max_lateral_rate = 0;         ///< 1/s, clamp of the servoed rates in shear; 0: 5 x axial_rate
  Real consolidation_rate = 0;       ///< 1/s, clamp of the servoed rates in consolidation; 0: max_lateral_rate
  /// 1/s, the clamp in consolidation while the balls' solid fraction is below gas_solid_fraction; 0: kGasRateFactor x
  /// consolidation_rate in a periodic cell, consolidation_rate between walls. Far from jamming the balls meet rarely
  /// and gently: at 4x the packings' state and curves stay within their seeds' scatter, at 10x the gas heats and
  /// packs otherwise (docs/performance.md, The gas phase).
  Real gas_rate = 0;
  Real gas_solid_fraction = 0.40;    ///< where the gas phase ends; at most kGasSolidFractionMax
  Real gas_volume = 0;               ///< m^3, the cell's volume at gas_solid_fraction (resolve_periodic_params)
  Real stress_tolerance = 0.005;     ///< consolidation: |sigma_ii - sigma3| / sigma3 on every axis
  Real unbalanced_tolerance = 1e-3;  ///< consolidation: unbalanced-force ratio
  long max_consolidation_steps = 2000000;
  long check_every = 100;            ///< consolidation: steps between convergence checks
  long stiffness_every = 10;         ///< steps between updates of the servo stiffness K_ii
  Real membrane_stiffness = 0;       ///< Pa, E_m t / R0 of the membrane extension in shear (0 = none)
  Real record_strain = 0.001;        ///< eps_a between series rows
  std::vector<Real> snapshot_strains{0, 0.01, 0.05, 0.15};  ///< eps_a of particle snapshots (with output)
  bool verbose = true;               ///< progress lines and the summary on stdout
};

/// Records a test's curve must have to its end strain ([triaxial] record_every_pct, [periodic] record_strain_pct).
inline constexpr long kMinRecords = 20;
inline constexpr long kAutoEnsemble = 0;
inline constexpr long kAutoCell = 0;
inline constexpr long kAutoBatch = 0;

/// [calibrate]: the parameters `triaxdem calibrate` and `diagnose` free (host/fit/calibrate.hpp lists the names).
struct CalibrateConfig {
  std::vector<std::string> free{"mu_s", "mu_r"};
  /// Specimens of the simulator's ensemble (packing seeds [run] seed, seed + 1, ...): every parameter point runs
  /// each of them and compares their mean (host/fit/misfit.hpp). kAutoEnsemble (the file's "auto"): the fewest of the
  /// scatter specimens whose mean's standard error is below half the data's noise (measure_misfit).
  long ensemble = kAutoEnsemble;
  /// Specimens on which the simulator's scatter is measured, once, at the base model (the first `ensemble` of
  /// them are the ensemble): a variance from few specimens is itself uncertain, and one that comes out small by
  /// chance turns a foreign specimen into a false alarm.
  long scatter_specimens = 16;
  /// The simulator's cell as a multiple of the config's balls (box sides times its cube root). kAutoCell (the
  /// file's "auto"): the config's cell, grown (host/fit/misfit.hpp, measure_misfit) only where an "auto" ensemble of
  /// all the scatter specimens still misses half the data's noise.
  long cell_factor = kAutoCell;
  /// Simulator runs (and specimen preparations) stepped side by side in one process (host/engine/cell_batch.hpp), at
  /// most this many at once: each bit for bit as alone. kAutoBatch (the file's "auto"): every run of a call at once on
  /// a GPU build, where one small cell uses a sliver of the device; 1 on a CPU, whose cores the runs share as child
  /// processes of one thread each (docs/engine.md, Many cells in one batch, measures both).
  long batch = kAutoBatch;
  /// The membrane test that `calibrate` and `diagnose` end with, at the calibrated parameters and the data's
  /// pressures (host/fit/prediction.hpp): a config with [specimen] and [triaxial], its path as the file gives it
  /// (relative to that file's folder); "" for none. `predict_specimens`: specimens (packing seeds) per pressure.
  std::string predict;
  long predict_specimens = 2;
  /// The test the calibration fits (host/fit/two_fidelity.hpp): "periodic" (the cell alone: it measures the grains
  /// inside a specimen, not the lab's boundary) or "two_fidelity" (the cell corrected by the `predict` membrane
  /// test at its optimum, then calibrated again).
  std::string reference_test = "periodic";
  /// How a walled cell smaller than the data's specimen is matched to the data's void ratio (host/lab/state_match.hpp):
  /// "whole" (the cell's own void ratio: its interior packs denser than the data's, its looser layer a larger share)
  /// or "interior" (as a specimen of the data's balls would pack, its walls' layer scaled to the data's size,
  /// host/lab/wall_layer.hpp). On YADE's 4,000-ball walled data the 1,000-ball cell fitted far better whole (chi2 61
  /// against 118 with mu_s free; docs/history/calibration.md): the data's strength follows the whole void ratio.
  std::string walled_match = "whole";
  /// How the search spends its runs (host/fit/calibrate.hpp): "ensemble" (every point the mean of the ensemble's
  /// specimens) or "one_specimen" (every point one specimen, in turn from the scatter specimens, and the response
  /// surfaces carry their scatter: OneSpecimenSearch). `diagnose` and two fidelities search with the ensemble.
  std::string method = "ensemble";
  /// method is "one_specimen".
  bool one_specimen() const { return method == "one_specimen"; }
};

/// The [periodic] table: the periodic-cell triaxial test (host/triax/periodic_triaxial.hpp).
/// The cell test's boundary (host/triax/cell_boundary.hpp): the periodic cell, or six rigid frictionless walls.
enum class CellBoundary { periodic, walls };

struct PeriodicConfig {
  PeriodicTriaxialParams triax;
  CellBoundary boundary = CellBoundary::periodic;
  /// Friction during a preparatory consolidation (YADE's compaction friction): below the test's mu_s
  /// gives a denser specimen. < 0: the material's value; both < 0: no preparatory stage (the test's own
  /// consolidation packs the specimen).
  Real prep_mu_s = -1, prep_mu_r = -1;
  /// Unbalanced-force ratio that ends the preparatory consolidation (the test's own consolidation then
  /// brings it to unbalanced_tolerance with the test's friction; frictionless packings creep for long).
  Real prep_unbalanced_tolerance = 1e-2;
};

struct Config {
  std::string path;  ///< file it came from (for messages)
  /// What decides a run's physics and outputs, as a hash of the file's settings ("" for a config built in code):
  /// a checkpoint carries it, so that --resume with another config is refused. The keys a continued run may
  /// change are left out: [run] steps, name, output, stop_ratio, checkpoint_every, checkpoint_minutes.
  std::string fingerprint;
  RunConfig run;
  ParticleConfig particles;
  BoxConfig box;
  ContactParams ball;   ///< ball-ball contact law
  ContactParams wall;   ///< ball-wall contact law (defaults to ball)
  SolverConfig solver;
  SpecimenConfig specimen;
  bool has_specimen = false;  ///< the file has a [specimen] table
  TriaxialConfig triaxial;
  MicroConfig micro;
  PeriodicConfig periodic;
  bool has_periodic = false;  ///< the file has a [periodic] table
  CalibrateConfig calibrate;
  /// Where packed cell specimens are kept and read back (host/lab/packing_store.hpp): a job sets it (calibrate,
  /// diagnose and synth: the output folder's .specimens/cells); never a key, so not in the fingerprint. "" keeps none.
  std::string packing_store;
};

/// The smallest time step a run takes, as a fraction of the critical step: quasi-static DEM runs at 0.1-0.3 of it,
/// and a step a thousand times smaller only multiplies the cost (dt_s = 1e-300 ran, and would never end).
constexpr Real kMinDtFraction = 1e-3;
/// A periodic cell's balls must fill at least this share of its box: it packs from a gas, and a box much emptier
/// never closes (a 120-ball cell starts near 0.05).
constexpr Real kMinSolidFraction = 1e-3;
/// The linear law's emod_Pa must be at least this many times the cell pressure: a contact loaded by sigma3 d^2
/// overlaps by about sigma3 / emod of a diameter, a tenth at this bound (glass beads: 1e8 Pa at 100 kPa, 1e-3).
constexpr Real kMinStiffnessOverPressure = 10;

/// The time step of a run: [solver] dt_s when set, else dt_safety x `critical` (s). Throws ConfigError naming
/// `path`, the key and the allowed range when dt_s is above the critical step or below kMinDtFraction of it.
Real time_step(const SolverConfig& solver, Real critical, const std::string& path);

/// Memory a run of `balls` balls needs at its peak (bytes): 667 bytes per ball in steady state
/// (perf/bench_engine: particle arrays and contact lists at 6-7 contacts per ball), doubled for the rebuild,
/// when the old and the new contact lists live side by side. perf/scaling.sh's peak resident memory at 10^6 balls
/// (docs/results.md, Cost per particle-step against the ball count) is some 15% above this, the program included.
constexpr double kBytesPerBall = 2 * 667;
/// Upper bound of a membrane node's memory, its triangles and facet contacts included (the config check).
constexpr double kBytesPerMembraneNode = 1000;
/// Refuses (ConfigError naming the key, the value and what is allowed) a periodic cell its balls cannot pack or its
/// linear law cannot carry at sigma3 (kMinSolidFraction, kMinStiffnessOverPressure).
void check_cell_physics(const Config& c);
double run_memory_bytes(long balls);

/// Reads and validates a config file. Throws ConfigError.
Config load_config(const std::string& path);
/// Every key the reader knows, as "table.key", with the kind of value it takes ("number", "integer", "boolean",
/// "string", "strings", "numbers", "triple", "booleans", "integer or word"): what the tests try bad values on.
std::map<std::string, std::string> config_keys();
/// The same from the file's text; `path` names it in errors.
Config parse_config(const std::string& text, const std::string& path);

}  // namespace dem
