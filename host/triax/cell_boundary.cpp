#include "host/triax/cell_boundary.hpp"

#include "host/engine/stress.hpp"
#include "kernels/core/reduce.hpp"
#include "host/engine/packing.hpp"
#include "host/triax/periodic_triaxial.hpp"
#include "host/engine/simulation.hpp"

namespace dem {

namespace {

/// A touching ball-wall contact's share of its wall's stiffness, Fn / overlap (for the six walls of the cell: wall
/// object o < 6 gets value o); no ball-ball terms.
struct WallStiffnessTerms {
  ConstVec3View x;
  ConstScalarView r;
  WallSet w;
  KOKKOS_INLINE_FUNCTION void ball(const ContactList&, int, int, Real*) const {}
  KOKKOS_INLINE_FUNCTION void wall(const ContactList& c, int s, int i, Real* v) const {
    const Real fn = c.fn(s);
    const int o = c.j(s);
    if (!(fn > 0) || o >= 6) return;
    const Real overlap = r(i) - dot(load(x, i) - load(w.point, o), load(w.normal, o));
    if (overlap > 0) v[o] = fn / overlap;
  }
};

}  // namespace

// Which axes are periodic never changes: the host's copy of the cell knows it without a read.
bool walled(const Simulation& sim) { return sim.num_walls() == 6 && !sim.params().domain.periodic[0]; }

std::vector<WallSpec> cell_walls(const std::array<Real, 3>& cell) {
  Config box;
  box.box.size = cell;
  box.box.periodic = {false, false, false};
  box.box.walls = true;
  return box_walls(box);
}

Vec3 cell_corner(const Simulation& sim) {
  const Domain& dom = sim.domain();
  if (!walled(sim)) return Vec3(dom.lo[0], dom.lo[1], dom.lo[2]);
  return Vec3(sim.wall_point(0).x, sim.wall_point(2).y, sim.wall_point(4).z);
}

std::array<Real, 3> cell_lengths(const Simulation& sim) {
  if (!walled(sim)) return {sim.domain().length(0), sim.domain().length(1), sim.domain().length(2)};
  const Vec3 lo = cell_corner(sim);
  return {sim.wall_point(1).x - lo.x, sim.wall_point(3).y - lo.y, sim.wall_point(5).z - lo.z};
}

Real cell_volume(const Simulation& sim) {
  if (!walled(sim)) return sim.domain().volume();
  const std::array<Real, 3> l = cell_lengths(sim);
  return l[0] * l[1] * l[2];
}

std::array<Real, 3> cell_stress(Simulation& sim) {
  if (!walled(sim)) return sim.contact_stress_diagonal(sim.domain().volume());
  return walled_cell_stress(sim.wall_forces(), cell_lengths(sim));
}

std::array<Real, 3> boundary_stiffness(Simulation& sim) {
  if (!walled(sim)) return sim.cell_stiffness();
  Real k[6];
  sim.owner_sums("dem::cell::wall_stiffness", WallStiffnessTerms{sim.particles().x, sim.particles().radius, sim.walls()},
                 k);
  const std::array<Real, 3> l = cell_lengths(sim);
  std::array<Real, 3> out{};
  for (int d = 0; d < 3; ++d)
    out[d] = 0.5 * (k[2 * d] + k[2 * d + 1]) * l[d] / (2 * l[(d + 1) % 3] * l[(d + 2) % 3]);
  return out;
}

void set_cell_rates(Simulation& sim, const Vec3& rate) {
  if (!walled(sim)) {
    sim.set_strain_rate(rate);
    return;
  }
  const std::array<Real, 3> l = cell_lengths(sim);
  std::vector<Vec3> v(6);
  for (int d = 0; d < 3; ++d) {
    Real e[3] = {0, 0, 0};
    e[d] = rate[d] * l[d] / 2;
    v[2 * d] = Vec3(-e[0], -e[1], -e[2]);
    v[2 * d + 1] = Vec3(e[0], e[1], e[2]);
  }
  sim.set_wall_velocities(v);
}

Vec3 cell_rates(const Simulation& sim) {
  if (!walled(sim)) return Vec3(sim.domain().strain_rate[0], sim.domain().strain_rate[1], sim.domain().strain_rate[2]);
  const std::array<Real, 3> l = cell_lengths(sim);
  Real r[3];
  for (int d = 0; d < 3; ++d)
    r[d] = (sim.wall_velocity(2 * d + 1)[d] - sim.wall_velocity(2 * d)[d]) / l[d];
  return Vec3(r[0], r[1], r[2]);
}

}  // namespace dem
