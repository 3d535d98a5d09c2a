#include "host/triax/triaxial_cell.hpp"

#include <algorithm>
#include <cmath>

#include "host/engine/setup.hpp"
#include "host/triax/triaxial_measure.hpp"

namespace dem {

Cell make_cell(const Config& cfg, const Specimen& sp) {
  const TriaxialConfig& tc = cfg.triaxial;
  Cell c;
  c.radius = cfg.specimen.diameter / 2;
  c.area = M_PI * c.radius * c.radius;
  const Real r_nodes = c.radius / std::cos(M_PI / tc.membrane_around);
  MembraneMaterial mat;
  mat.young = tc.membrane_modulus;
  mat.poisson = tc.membrane_poisson;
  mat.thickness = tc.membrane_thickness;
  mat.density = tc.membrane_density;
  c.membrane = make_membrane(make_cylinder_membrane(tc.membrane_around, tc.membrane_segments, r_nodes, 0, sp.height),
                             mat, 1);
  std::vector<WallSpec> w(2);
  w[kBottomPlaten].normal = Vec3(0, 0, 1);
  w[kTopPlaten].point = Vec3(0, 0, sp.height);
  w[kTopPlaten].normal = Vec3(0, 0, -1);
  for (auto& x : w) x.material = 1;
  SimParams prm = solver_params(cfg);
  // Bounds far outside anything the membrane can bulge to: a ball beyond them has escaped (a blow-up).
  for (int d = 0; d < 2; ++d) prm.domain.lo[d] = -2 * c.radius, prm.domain.hi[d] = 2 * c.radius;
  prm.domain.lo[2] = -0.5 * sp.height;
  prm.domain.hi[2] = 1.5 * sp.height;
  std::vector<BallSpec> balls = sp.balls;
  Real r_max = 0;
  for (const BallSpec& b : balls) r_max = std::max(r_max, b.radius);
  sort_like_cells(balls, 2 * r_max);
  c.sim = std::make_unique<Simulation>(make_particles(balls), make_walls(w), c.membrane.mesh,
                                       std::vector<ContactParams>{cfg.ball, cfg.wall, cfg.wall, cfg.wall}, 2, prm);
  MembraneIntegrateParams mp;
  mp.gravity = prm.integ.gravity;
  mp.alpha = cfg.solver.damping;
  mp.mass_scale = cfg.solver.mass_scale;
  c.sim->set_membrane(c.membrane, mp);
  c.sim->set_cell_pressure(cfg.triaxial.sigma3);
  c.sim->set_dt(time_step(cfg.solver, c.sim->critical_dt(), cfg.path));
  c.kn_wall = ContactLaws::servo_stiffness(cfg.wall, cfg.particles.diameter / 2, 0);
  c.solid_volume = solid_volume(sp.balls);
  for (const BallSpec& b : sp.balls) c.mean_radius += b.radius / sp.balls.size();
  return c;
}

void set_top_velocity(Cell& c, Real vz) {
  c.sim->set_wall_velocity(kTopPlaten, Vec3(0, 0, vz));
  auto ring = c.membrane.ring_top;
  auto v = c.membrane.mesh.node_v;
  Kokkos::parallel_for("dem::triaxial::tie_ring", RangePolicy(0, ring.extent(0)), KOKKOS_LAMBDA(const int k) {
    v(ring(k), 0) = 0;
    v(ring(k), 1) = 0;
    v(ring(k), 2) = vz;
  });
}

std::pair<Real, Real> platen_stresses(const Cell& c, const std::vector<Vec3>& f) {
  return {f[kTopPlaten].z / c.area, -f[kBottomPlaten].z / c.area};
}

Real specimen_volume(const Cell& c) { return enclosed_volume(c.membrane, 0, c.sim->wall_point(kTopPlaten).z); }

}  // namespace dem
