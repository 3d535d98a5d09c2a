#include "host/engine/stress.hpp"

#include "host/engine/simulation.hpp"
#include "kernels/contact/contact_sums.hpp"
#include "kernels/core/reduce.hpp"

namespace dem {

namespace {

void add_term(Tensor& t, const Vec3& f, const Vec3& l, Real volume) {
  Real v[9];
  love_weber_term<9>(f, l, v);
  for (int q = 0; q < 9; ++q) t[q] += v[q] / volume;
}

}  // namespace

void add_love_weber(Tensor& t, const ContactRecord& c, Real volume) {
  add_term(t, c.fn * c.normal + c.ft, c.branch, volume);
}

Real axial_deviator(const std::array<Real, 3>& s) { return s[2] - (s[0] + s[1]) / 2; }

Real axial_deviator(const Tensor& t) { return axial_deviator(std::array<Real, 3>{t[0], t[4], t[8]}); }

Real mean_stress(const std::array<Real, 3>& s) { return (s[0] + s[1] + s[2]) / 3; }

Real mean_stress(const Tensor& t) { return mean_stress(std::array<Real, 3>{t[0], t[4], t[8]}); }

Real triaxial_mean_stress(Real sigma3, Real q) { return sigma3 + q / 3; }

Real stress_ratio(const Tensor& s) {
  const Real p = mean_stress(s);
  return p > 0 ? axial_deviator(s) / p : 0;
}

Tensor love_weber(const ContactSet& s, Real volume, bool include_boundary) {
  Tensor t{};
  for (const ContactRecord& c : s.contacts)
    if ((c.boundary == Boundary::kNone || include_boundary) && c.in_volume) add_love_weber(t, c, volume);
  return t;
}

Tensor boundary_stress(const ContactSet& s, Real volume) {
  Tensor t{};
  for (const ContactRecord& c : s.contacts)
    if (c.boundary != Boundary::kNone && c.in_volume) add_term(t, c.fn * c.normal + c.ft, c.point, volume);
  return t;
}

SpecimenStress specimen_stress(const Simulation& sim, Real volume) {
  const ContactOwners owners = sim.contact_owners();
  const Particles& p = sim.particles_with_forces();
  const SpecimenStressTerms terms{p.x, MinImage(sim.domain()), sim.walls(), sim.mesh()};
  Real s[27];
  deterministic_reduce_lanes<27, 0, 1>("dem::stress::specimen", static_cast<int>(owners.gid2local.extent(0)),
                                       SpecimenStressSums{OwnerSums<27, SpecimenStressTerms>{owners, terms}, p.f}, s);
  SpecimenStress out;
  for (int q = 0; q < 9; ++q) {
    out.love_weber[q] = s[q] / volume;
    out.boundary[q] = s[9 + q] / volume;
    out.net_force[q] = s[18 + q] / volume;
  }
  return out;
}

Real lateral_stress(const ContactCopy& state, int w0, const std::vector<Vec3>& f) {
  const auto& nx = state.node_x;
  const auto& tri = state.tri;
  const auto& fixed = state.fixed;
  Real fn = 0, area = 0;
  for (int t = 0; t < state.ntri; ++t) {
    if (fixed(tri(t, 0)) || fixed(tri(t, 1)) || fixed(tri(t, 2))) continue;
    const Vec3 a = load(nx, tri(t, 0)), b = load(nx, tri(t, 1)), d = load(nx, tri(t, 2));
    const Vec3 s = 0.5 * cross(b - a, d - a);  // area vector, outward (counter-clockwise seen from outside)
    fn += dot(f[w0 + t], s) / norm(s);
    area += norm(s);
  }
  return area > 0 ? fn / area : 0;
}

std::array<Real, 3> walled_cell_stress(const std::vector<Vec3>& f, const std::array<Real, 3>& l) {
  std::array<Real, 3> s{};
  for (int d = 0; d < 3; ++d) {
    // The balls push the lower wall towards -d and the upper one towards +d.
    const Real push = 0.5 * (f[2 * d + 1][d] - f[2 * d][d]);
    s[d] = push / (l[(d + 1) % 3] * l[(d + 2) % 3]);
  }
  return s;
}

}  // namespace dem
