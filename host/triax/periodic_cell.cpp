/// The periodic cell's set-up (a Simulation on a periodic box, its specimen, the balls back out of it); the test
/// itself is in periodic_triaxial.cpp, the `periodic` command in host/cli/triaxial_jobs.cpp.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "host/config/size_distribution.hpp"
#include "host/triax/cell_boundary.hpp"
#include "host/engine/checkpoint.hpp"
#include "host/engine/setup.hpp"
#include "host/engine/packing.hpp"
#include "host/triax/periodic_triaxial.hpp"
#include "host/triax/summary.hpp"

namespace dem {

const char* cell_name(CellBoundary b) {
  return b == CellBoundary::walls ? "a cuboid between six walls" : "a periodic cell";
}

std::unique_ptr<Simulation> make_periodic_simulation(const std::vector<BallSpec>& balls,
                                                     const std::array<Real, 3>& cell, const ContactParams& law,
                                                     const SolverConfig& solver, CellBoundary boundary) {
  if (balls.empty()) throw std::invalid_argument("periodic triaxial: no balls");
  Real dmean = 0;
  for (const BallSpec& b : balls) dmean += 2 * b.radius;
  dmean /= static_cast<Real>(balls.size());
  const bool walls = boundary == CellBoundary::walls;
  SimParams prm;
  for (int k = 0; k < 3; ++k) {
    prm.domain.lo[k] = 0;
    prm.domain.hi[k] = cell[k];
    prm.domain.periodic[k] = !walls;
  }
  prm.integ.gravity = Vec3();
  prm.integ.alpha = solver.damping;
  prm.integ.mass_scale = solver.mass_scale;
  prm.skin = solver.skin * dmean;
  prm.overlap_limit = solver.overlap_limit;
  prm.stats_every = stats_every_of(solver);
  std::vector<BallSpec> b = balls;
  for (BallSpec& s : b) s.material = 0;
  std::unique_ptr<Simulation> sim;
  if (walls) {
    ContactParams smooth = law;  // walls without friction, as a walled test's lubricated or polished walls
    smooth.mu_s = smooth.mu_r = 0;
    sim = std::make_unique<Simulation>(make_particles(b), make_walls(cell_walls(cell)), FacetMesh(),
                                       std::vector<ContactParams>{law, smooth, smooth, smooth}, 2, prm);
  } else {
    sim = std::make_unique<Simulation>(make_particles(b), WallSet(), FacetMesh(), std::vector<ContactParams>{law}, 1,
                                       prm);
  }
  sim->set_dt(time_step(solver, sim->critical_dt(), "the periodic cell's config"));
  return sim;
}

namespace {

/// The balls in gid order: the constants of `p` (radius, density from the mass, specimen, material) and the state
/// `h` (by gid), positions wrapped into `dom` (a periodic cell) and taken from `corner`.
std::vector<BallSpec> balls_by_gid(const Particles& p, const HostParticles& h, const Domain& dom, bool walls,
                                   const Vec3& corner) {
  auto gid = Kokkos::create_mirror_view_and_copy(HostSpace(), p.gid);
  auto rad = Kokkos::create_mirror_view_and_copy(HostSpace(), p.radius);
  auto mass = Kokkos::create_mirror_view_and_copy(HostSpace(), p.mass);
  auto spec = Kokkos::create_mirror_view_and_copy(HostSpace(), p.specimen);
  auto mat = Kokkos::create_mirror_view_and_copy(HostSpace(), p.material);
  std::vector<BallSpec> out(p.n);
  for (int i = 0; i < p.n; ++i) {
    BallSpec& b = out[gid(i)];
    b.radius = rad(i);
    b.density = mass(i) / (4.0 / 3.0 * M_PI * rad(i) * rad(i) * rad(i));
    b.specimen = spec(i);
    b.material = mat(i);
  }
  for (int k = 0; k < p.n; ++k) {
    out[k].x = (walls ? h.x[k] : dom.wrap(h.x[k])) - corner;
    out[k].v = h.v[k];
    out[k].w = h.w[k];
  }
  return out;
}

}  // namespace

std::vector<BallSpec> extract_balls(Simulation& sim, std::array<Real, 3>& cell) {
  cell = cell_lengths(sim);
  return balls_by_gid(sim.particles(), to_host_by_gid(sim.particles()), sim.domain(), walled(sim), cell_corner(sim));
}

void check_periodic_config(const Config& cfg) {
  const bool walls = cfg.periodic.boundary == CellBoundary::walls;
  if (!walls && !(cfg.box.periodic[0] && cfg.box.periodic[1] && cfg.box.periodic[2]))
    throw ConfigError(cfg.path + ": [box] periodic: the periodic triaxial needs [true, true, true] (or [periodic] "
                      "boundary = \"walls\")");
  if (cfg.solver.gravity[0] != 0 || cfg.solver.gravity[1] != 0 || cfg.solver.gravity[2] != 0)
    throw ConfigError(cfg.path + ": [solver] gravity: must be [0, 0, 0] in the cell test");
  if (walls) return;  // no minimum image between walls
  // Consolidation shrinks the cell and shear shortens its axis: at random close packing (solid fraction 0.64,
  // the densest a packing of spheres reaches unloaded) and the end strain, each side must still hold 3
  // contact cut-offs, or the minimum image becomes ambiguous and the run stops part way. 5% more for the
  // overlaps under load (a 64-ball cell at 1.03 times the limit by this estimate ended 0.1% short of it).
  const ParticleConfig& pc = cfg.particles;
  const SizeDistribution sizes(pc);
  const Real cutoff = sizes.largest() + cfg.solver.skin * pc.diameter;
  const Real box = cfg.box.size[0] * cfg.box.size[1] * cfg.box.size[2];
  const Real dense = std::cbrt(static_cast<Real>(pc.count) * M_PI / 6 * sizes.mean_cube() / 0.64 / box);
  const Real shortest = dense * std::min({cfg.box.size[0], cfg.box.size[1], cfg.box.size[2]}) *
                        (1 - cfg.periodic.triax.target_strain);
  if (shortest < 1.05 * 3 * cutoff) {
    const Real need = std::ceil(pc.count * std::pow(1.05 * 3 * cutoff / shortest, 3));
    throw ConfigError(cfg.path + ": [particles] count: " + std::to_string(pc.count) + " balls consolidate to a "
                      "periodic cell whose shortest side (about " + std::to_string(1e3 * shortest) +
                      " mm at the end strain) holds fewer than 3 contact cut-offs and 5% (" +
                      std::to_string(1.05 * 3e3 * cutoff) +
                      " mm); allowed: at least " + std::to_string(static_cast<long>(need)) + " balls in this box shape");
  }
}

namespace {

/// A specimen's packing (of [particles]/[box]) and, where the preparation's friction differs from the material's,
/// the Simulation that consolidates it and the stage's parameters; `balls` and `cell` receive the packing.
std::unique_ptr<Simulation> packing_of(const Config& cfg, std::vector<BallSpec>& balls, std::array<Real, 3>& cell,
                                       PeriodicTriaxialParams& pp, bool verbose) {
  check_periodic_config(cfg);
  const PeriodicConfig& pc = cfg.periodic;
  Config inside = cfg;  // between walls every ball starts inside the box
  if (pc.boundary == CellBoundary::walls) inside.box.periodic = {false, false, false};
  balls = make_packing(inside);
  cell = cfg.box.size;
  if (verbose && cfg.particles.psd != SizeLaw::uniform) {
    // What was drawn, beside the table: a lab compares its sieve curve with the specimen's.
    const SizeDistribution sizes(cfg.particles);
    Real mean = 0, lo = balls.empty() ? 0 : 2 * balls[0].radius, hi = lo;
    for (const BallSpec& b : balls) {
      mean += 2 * b.radius;
      lo = std::min(lo, 2 * b.radius);
      hi = std::max(hi, 2 * b.radius);
    }
    std::printf("triaxdem: sizes: %s distribution, %.4g to %.4g mm, mean %.4g mm by number; drawn: %.4g to %.4g mm, "
                "mean %.4g mm\n", cfg.particles.psd == SizeLaw::sieve ? "sieve" : "lognormal",
                1e3 * sizes.smallest(), 1e3 * sizes.largest(), 1e3 * sizes.mean(), 1e3 * lo, 1e3 * hi,
                1e3 * mean / std::max<std::size_t>(balls.size(), 1));
  }
  ContactParams prep = cfg.ball.base();
  if (pc.prep_mu_s >= 0) prep.mu_s = pc.prep_mu_s;
  if (pc.prep_mu_r >= 0) prep.mu_r = pc.prep_mu_r;
  // Without a preparation friction the test's own consolidation packs the specimen. One that is set packs it here
  // even where it equals the material's: a state match reads the packing's void ratio (a frictionless material's
  // match at preparation friction 0 read the generated cloud's 5.07 and blamed the data).
  if (pc.prep_mu_s < 0 && pc.prep_mu_r < 0) return nullptr;
  auto sim = make_periodic_simulation(balls, cell, prep, cfg.solver, pc.boundary);
  if (verbose)
    std::printf("triaxdem: preparation: %zu balls in %s %.2f x %.2f x %.2f mm, consolidated with "
                "mu_s = %g, mu_r = %g; dt %.3e s\n", balls.size(), cell_name(pc.boundary), 1e3 * cell[0],
                1e3 * cell[1], 1e3 * cell[2], prep.mu_s, prep.mu_r, sim->params().integ.dt);
  pp = resolve_periodic_params(*sim, pc.triax);
  pp.name = cfg.run.name + " preparation";
  pp.verbose = verbose;
  pp.unbalanced_tolerance = pc.prep_unbalanced_tolerance;
  return sim;
}

}  // namespace

long prepare_periodic_specimen(const Config& cfg, std::vector<BallSpec>& balls, std::array<Real, 3>& cell,
                               bool verbose, std::unique_ptr<Simulation>* keep) {
  PeriodicTriaxialParams pp;
  std::unique_ptr<Simulation> own;
  std::unique_ptr<Simulation>& sim = keep ? *keep : own;
  sim = packing_of(cfg, balls, cell, pp, verbose);
  if (!sim) return 0;
  const long steps = consolidate_isotropic(*sim, pp).timing.steps;
  balls = extract_balls(*sim, cell);
  return steps;
}

std::vector<PreparedCell> prepare_periodic_specimens(const std::vector<Config>& cfgs) {
  std::vector<PreparedCell> out(cfgs.size());
  std::vector<std::unique_ptr<Simulation>> made(cfgs.size());
  std::vector<Simulation*> sims;
  std::vector<PeriodicTriaxialParams> prms;
  std::vector<std::size_t> consolidated;  // the specimens with a preparation stage
  for (std::size_t k = 0; k < cfgs.size(); ++k) {
    PeriodicTriaxialParams pp;
    made[k] = packing_of(cfgs[k], out[k].balls, out[k].cell, pp, false);
    if (!made[k]) continue;
    pp.verbose = false;
    sims.push_back(made[k].get());
    prms.push_back(pp);
    consolidated.push_back(k);
  }
  if (sims.empty()) return out;
  // Walls are not batched (CellBatch takes periodic cells): each such specimen consolidates alone.
  if (cfgs.front().periodic.boundary == CellBoundary::walls) {
    for (std::size_t j = 0; j < consolidated.size(); ++j) {
      const std::size_t k = consolidated[j];
      consolidate_isotropic(*made[k], prms[j]);
      out[k].balls = extract_balls(*made[k], out[k].cell);
    }
    return out;
  }
  const std::vector<BatchedTest> runs = run_periodic_batch(sims, prms, true);
  for (std::size_t j = 0; j < runs.size(); ++j) {  // the first failure, as one at a time would meet it
    if (!runs[j].blowup.empty()) throw BlowUp(runs[j].blowup);
    if (!runs[j].failure.empty()) throw std::runtime_error(runs[j].failure);
    const std::size_t k = consolidated[j];
    const Domain& dom = runs[j].domain;
    out[k].cell = {dom.length(0), dom.length(1), dom.length(2)};
    out[k].balls = balls_by_gid(made[k]->particles(), runs[j].balls, dom, false, Vec3(dom.lo[0], dom.lo[1], dom.lo[2]));
  }
  return out;
}

}  // namespace dem
