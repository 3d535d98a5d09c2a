#include "host/lab/run_cost.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iterator>

#include "host/config/size_distribution.hpp"
#include "host/engine/builder.hpp"
#include "host/engine/cell_batch.hpp"
#include "host/triax/periodic_triaxial.hpp"
#include "host/triax/specimen.hpp"
#include "host/triax/triaxial.hpp"

namespace dem {

namespace {
/// The axial rate of a run at sigma3 (resolve_periodic_params): given, or I = rate d sqrt(rho_eff / sigma3).
Real axial_rate(const PeriodicTriaxialParams& p, Real d, Real rho_eff, Real sigma3) {
  return p.axial_rate > 0 ? p.axial_rate : p.target_inertial / (d * std::sqrt(rho_eff / sigma3));
}
}  // namespace

long CellCost::shear_steps(Real sigma3) const {
  return shear_step_count(triax.target_strain, axial_rate(triax, d, rho_eff, sigma3), dt);
}

long CellCost::settling_steps(bool high) const {
  return resettles() ? static_cast<long>((high ? ResettleCost::high : ResettleCost::low) * packing_steps) : 0;
}

long CellCost::consolidation_steps(Real sigma3, bool high) const {
  return static_cast<long>(kConsolidationShare * static_cast<Real>(shear_steps(sigma3))) + settling_steps(high);
}

long CellCost::compression_steps(std::size_t increments, bool high) const {
  const Real holds = static_cast<Real>(increments + 1) * (high ? HoldChecks::high : HoldChecks::low) *
                     static_cast<Real>(triax.check_every);
  return static_cast<long>(holds) + settling_steps(high);
}

namespace {

/// A cubic lattice of the cell's balls (at most kMaxProbeBalls), each pressed into its six neighbours by 0.1% of its
/// diameter: a probe with the contacts of a loaded packing (the gas phase of a random insertion would time a cheaper
/// step).
std::vector<BallSpec> probe_lattice(const Config& cell, std::array<Real, 3>& box) {
  const ParticleConfig& pc = cell.particles;
  const long count = std::min(pc.count, kMaxProbeBalls);
  const long n = static_cast<long>(std::ceil(std::cbrt(static_cast<Real>(count))));
  const Real pitch = 0.999 * pc.diameter;
  std::vector<BallSpec> balls;
  for (long k = 0; k < n * n * n && static_cast<long>(balls.size()) < count; ++k) {
    BallSpec b;
    b.x = Vec3((k % n + 0.5) * pitch, ((k / n) % n + 0.5) * pitch, (k / (n * n) + 0.5) * pitch);
    b.radius = pc.diameter / 2;
    b.density = pc.density;
    balls.push_back(b);
  }
  box = {n * pitch, n * pitch, n * pitch};
  return balls;
}

/// Cells in the probe's batch for a batch's growth: on a GPU many cells share a step's launches, and the time of a
/// batch grows nearly linearly to hundreds of cells (BM_CellBatch: 64 cells 33 times one alone, 512 cells 85 times,
/// the fifth device run), so a few tens show the slope at a probe's cost.
constexpr int kGrowthProbeCells = 16;

/// Seconds a step takes, `advance` taking ten: once untimed, as the first steps build the lists and touch the memory,
/// then timed until at least `min_steps` steps and `seconds`.
template <class Advance>
double seconds_per_step(Advance advance, long min_steps, double seconds) {
  advance();
  long steps = 0;
  const auto t0 = std::chrono::steady_clock::now();
  double elapsed = 0;
  while (steps < min_steps || elapsed < seconds) {
    advance();
    steps += 10;
    elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  return elapsed / static_cast<double>(steps);
}

/// Seconds a step of `cells` copies of the lattice takes as one batch, stepped for about `seconds` (at least 20
/// steps).
double batch_step_seconds(const Config& cell, const std::vector<BallSpec>& balls, const std::array<Real, 3>& box,
                          int cells, double seconds) {
  std::vector<std::unique_ptr<Simulation>> sims;
  std::vector<const Simulation*> specimens;
  for (int k = 0; k < cells; ++k) {
    sims.push_back(make_periodic_simulation(balls, box, cell.ball, cell.solver, CellBoundary::periodic));
    specimens.push_back(sims.back().get());
  }
  CellBatch batch(specimens);
  return seconds_per_step([&] { for (int k = 0; k < 10; ++k) batch.step(); }, 20, seconds);
}

}  // namespace

int batch_in_effect(long batch, const Config& cell) {
  if (batch == kAutoBatch) batch = kOnDevice ? 4096 : 1;
  if (cell.periodic.boundary == CellBoundary::walls) batch = 1;
  return static_cast<int>(std::max(1L, batch));
}

double side_by_side_seconds(double n, double each, int at_once) {
  return std::ceil(n / std::max(at_once, 1) - 1e-9) * each;
}

double CellCost::seconds_of(double n, double each, int at_once) const {
  if (batch <= 1) return side_by_side_seconds(n, each, at_once);
  const double full = std::floor(n / batch + 1e-9), rest = n - full * batch;
  const auto one = [&](double k) { return k > 0 ? each * (1 + (k - 1) * batch_growth) : 0.0; };
  return full * one(batch) + one(rest);
}

CellCost measure_cell_cost(const Config& cell, double probe_seconds) {
  CellCost c;
  c.balls = cell.particles.count;
  std::array<Real, 3> box{};
  const std::vector<BallSpec> balls = probe_lattice(cell, box);
  c.probed_balls = static_cast<long>(balls.size());
  auto sim = make_periodic_simulation(balls, box, cell.ball, cell.solver, CellBoundary::periodic);
  c.dt = sim->params().integ.dt;
  c.d = cell.particles.diameter;  // the mean of diameters uniform between the smallest and the largest
  c.rho_eff = cell.particles.density * cell.solver.mass_scale;
  c.triax = cell.periodic.triax;
  c.mu_s = cell.ball.mu_s;
  const double step_s = seconds_per_step([&] { sim->run(10); }, 50, probe_seconds);
  c.ns_per_particle_step = 1e9 * step_s / static_cast<double>(balls.size()) * kPairsOverLattice;
  c.batch = batch_in_effect(cell.calibrate.batch, cell);
  if (c.batch > 1) {
    const int k = std::min(c.batch, kGrowthProbeCells);
    const double one = batch_step_seconds(cell, balls, box, 1, probe_seconds);
    c.batch_growth = std::max(0.0, (batch_step_seconds(cell, balls, box, k, probe_seconds) / one - 1) / (k - 1));
  }
  // The gas phase: the cell closes on every axis from the box's solid fraction to a dense packing's, at the gas
  // phase's clamp to gas_solid_fraction and at the consolidation rate's after (resolve_periodic_params' defaults).
  const Real volume = cell.box.size[0] * cell.box.size[1] * cell.box.size[2];
  const Real solid = static_cast<Real>(c.balls) * M_PI / 6 * SizeDistribution(cell.particles).mean_cube() / volume;
  const Real axial = axial_rate(c.triax, c.d, c.rho_eff, c.triax.sigma3);
  const Real rate = c.triax.consolidation_rate > 0
                        ? c.triax.consolidation_rate
                        : (c.triax.max_lateral_rate > 0 ? c.triax.max_lateral_rate : 5 * axial);
  const Real gas_rate = std::max(rate, c.triax.gas_rate > 0 ? c.triax.gas_rate
                                       : (cell.periodic.boundary == CellBoundary::walls ? 1 : kGasRateFactor) * rate);
  const Real gas_end = std::max(solid, std::min(c.triax.gas_solid_fraction, kPackedSolidFraction));
  auto closing = [&](Real from, Real to, Real r) { return std::max(Real(0), std::log(to / from) / 3) / (r * c.dt); };
  const Real gas = closing(solid, gas_end, gas_rate) + closing(gas_end, kPackedSolidFraction, rate);
  c.packing_steps = static_cast<long>(kPackingStepsOverGas * gas);
  return c;
}

PackingCost packing_cost_at(Real prep_mu_s) {
  // In sqrt(mu), as the state match bisects; linear between the measured points (run_cost.hpp).
  struct Point {
    double root, low, high;
  };
  static constexpr Point kPoints[] = {{0, 2.3, 3.6},  {0.05, 1.4, 2.1}, {0.1, 1.2, 1.8},
                                      {0.2, 0.9, 1.3}, {0.55, 0.6, 1.0}, {1, 1.0, 1.5}};
  const double u = std::sqrt(std::clamp(static_cast<double>(prep_mu_s), 0.0, 1.0));
  for (std::size_t k = 1; k < std::size(kPoints); ++k) {
    const Point& a = kPoints[k - 1];
    const Point& b = kPoints[k];
    if (u > b.root) continue;
    const double t = (u - a.root) / (b.root - a.root);
    return {a.low + t * (b.low - a.low), a.high + t * (b.high - a.high)};
  }
  return {kPoints[std::size(kPoints) - 1].low, kPoints[std::size(kPoints) - 1].high};
}

MembraneCost::MembraneCost(const Config& membrane) : cfg(membrane) {
  cfg.particles.count = specimen_ball_count(membrane);
  cell = measure_cell_cost(cfg);
}

double MembraneCost::steps(Real sigma3) const {
  Config c = cfg;
  c.triaxial.sigma3 = sigma3;
  const ShearPlan p = shear_plan(c, cell.dt);
  return (1 + kConsolidationShare) * static_cast<double>(p.ramp + p.steps);
}

double MembraneCost::seconds(Real sigma3) const {
  return 1e-9 * kMembraneStepOverCell * cell.ns_per_particle_step * cell.balls * steps(sigma3);
}

}  // namespace dem
