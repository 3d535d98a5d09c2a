#include "host/engine/setup.hpp"

#include <cstdio>
#include <numeric>

#include "host/engine/packing.hpp"

namespace dem {

int stats_every_of(const SolverConfig& solver) {
  if (solver.stats_every > 0) return static_cast<int>(solver.stats_every);
  return kOnDevice ? 16 : 1;
}

SimParams solver_params(const Config& cfg) {
  SimParams prm;
  prm.integ.gravity = Vec3(cfg.solver.gravity[0], cfg.solver.gravity[1], cfg.solver.gravity[2]);
  prm.integ.alpha = cfg.solver.damping;
  prm.integ.mass_scale = cfg.solver.mass_scale;
  prm.skin = cfg.solver.skin * cfg.particles.diameter;
  prm.overlap_limit = cfg.solver.overlap_limit;
  prm.stats_every = stats_every_of(cfg.solver);
  return prm;
}

std::unique_ptr<Simulation> build_simulation(const Config& cfg, bool verbose) {
  // An open side under gravity holds nothing in: the first ball out stopped the run as a blow-up that blamed a wall.
  if (!cfg.box.walls)
    for (int k = 0; k < 3; ++k)
      if (!cfg.box.periodic[k] && cfg.solver.gravity[k] != 0)
        throw ConfigError(cfg.path + ": [box] walls = false with [solver] gravity along " + "xyz"[k] +
                          ": nothing holds the balls in the box (allowed: walls = true, a box periodic along that "
                          "axis, or no gravity along it)");
  std::vector<BallSpec> balls = make_packing(cfg);
  std::vector<WallSpec> walls = box_walls(cfg);
  SimParams prm = solver_params(cfg);
  for (int k = 0; k < 3; ++k) {
    prm.domain.lo[k] = 0;
    prm.domain.hi[k] = cfg.box.size[k];
    prm.domain.periodic[k] = cfg.box.periodic[k];
  }
  // Material 0: balls, material 1: walls; ball-wall contacts use the wall material's law.
  const std::vector<ContactParams> table = {cfg.ball, cfg.wall, cfg.wall, cfg.wall};
  auto sim = std::make_unique<Simulation>(make_particles(balls), make_walls(walls), FacetMesh(), table, 2, prm);
  const Real crit = sim->critical_dt();
  const Real dt = time_step(cfg.solver, crit, cfg.path);
  sim->set_dt(dt);
  if (verbose) {
    std::printf("triaxdem: %zu balls, %zu walls; critical dt %.3e s, dt %.3e s (%s)\n", balls.size(), walls.size(),
                crit, dt, cfg.solver.dt > 0 ? "set by [solver] dt_s" : "dt_safety x critical");
    if (cfg.solver.mass_scale != 1)
      std::printf("triaxdem: DENSITY SCALING x%g is on: inertia is not physical (quasi-static runs only)\n",
                  cfg.solver.mass_scale);
  }
  return sim;
}

io::Snapshot take_snapshot(Simulation& sim, const std::string& label) {
  Particles& p = sim.particles();
  const HostParticles h = to_host_by_gid(p);
  io::Snapshot s;
  s.step = sim.step_count();
  s.time = sim.time();
  s.label = label;
  auto gid = Kokkos::create_mirror_view_and_copy(HostSpace(), p.gid);
  auto rad = Kokkos::create_mirror_view_and_copy(HostSpace(), p.radius);
  auto spec = Kokkos::create_mirror_view_and_copy(HostSpace(), p.specimen);
  s.radius.resize(p.n);
  s.specimen.resize(p.n);
  s.gid.resize(p.n);
  std::iota(s.gid.begin(), s.gid.end(), 0u);
  for (int i = 0; i < p.n; ++i) {
    s.radius[gid(i)] = rad(i);
    s.specimen[gid(i)] = spec(i);
  }
  for (int i = 0; i < p.n; ++i)
    for (int d = 0; d < 3; ++d) {
      s.x.push_back(h.x[i][d]);
      s.v.push_back(h.v[i][d]);
      s.w.push_back(h.w[i][d]);
    }
  return s;
}

Config packed_lattice(const Config& base, int side, bool periodic) {
  Config c = base;
  c.particles.count = static_cast<long>(side) * side * side;
  c.particles.diameter_ratio = 1;
  c.box.fill = "lattice";
  c.box.lattice_spacing = 0.995;
  const Real pitch = c.box.lattice_spacing * c.particles.diameter;
  for (int k = 0; k < 3; ++k) {
    c.box.periodic[k] = periodic;
    c.box.size[k] = periodic ? side * pitch : (side - 1) * pitch + c.particles.diameter * 1.0005;
  }
  c.box.walls = !periodic;
  c.solver.gravity = {0, 0, 0};
  return c;
}

}  // namespace dem
