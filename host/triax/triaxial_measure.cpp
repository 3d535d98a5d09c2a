#include "host/triax/triaxial_measure.hpp"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "host/engine/builder.hpp"
#include "host/engine/simulation.hpp"

namespace dem {

namespace {

/// Area of the convex hull of discs of radius r centred at `pts` (m^2): hull of the centres (Andrew's
/// monotone chain) grown by r, i.e. A_hull + r P_hull + pi r^2.
Real disc_hull_area(std::vector<std::pair<Real, Real>> pts, Real r) {
  std::sort(pts.begin(), pts.end());
  pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
  if (pts.size() < 3) return M_PI * r * r;
  auto turn = [](const std::pair<Real, Real>& o, const std::pair<Real, Real>& a, const std::pair<Real, Real>& b) {
    return (a.first - o.first) * (b.second - o.second) - (a.second - o.second) * (b.first - o.first);
  };
  std::vector<std::pair<Real, Real>> h(2 * pts.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    while (k >= 2 && turn(h[k - 2], h[k - 1], pts[i]) <= 0) --k;
    h[k++] = pts[i];
  }
  for (std::size_t i = pts.size() - 1, t = k + 1; i > 0; --i) {
    while (k >= t && turn(h[k - 2], h[k - 1], pts[i - 1]) <= 0) --k;
    h[k++] = pts[i - 1];
  }
  h.resize(k - 1);
  Real area = 0, perimeter = 0;
  for (std::size_t i = 0; i < h.size(); ++i) {
    const auto& a = h[i];
    const auto& b = h[(i + 1) % h.size()];
    area += 0.5 * (a.first * b.second - b.first * a.second);
    perimeter += std::hypot(b.first - a.first, b.second - a.second);
  }
  return area + r * perimeter + M_PI * r * r;
}

/// True when the horizontal ray from x away from the axis crosses triangle (a, b, c) (Moller-Trumbore).
bool ray_crosses(const Vec3& x, const Vec3& dir, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 e1 = b - a, e2 = c - a, p = cross(dir, e2);
  const Real det = dot(e1, p);
  if (std::fabs(det) < 1e-300) return false;
  const Vec3 s = x - a;
  const Real u = dot(s, p) / det;
  if (u < 0 || u > 1) return false;
  const Vec3 q = cross(s, e1);
  const Real v = dot(dir, q) / det;
  if (v < 0 || u + v > 1) return false;
  return dot(e2, q) / det > 0;
}

}  // namespace

Real right_cylinder_area(Real a0, Real eps_a, Real eps_v) { return a0 * (1 - eps_v) / (1 - eps_a); }

Real parabolic_mid_area(Real a0, Real eps_a, Real eps_v) {
  // The volume of the parabolic barrel, pi h (8 r_m^2 + 4 r_m r0 + 3 r0^2) / 15, set equal to k pi r0^2 h.
  const Real k = (1 - eps_v) / (1 - eps_a);
  const Real ratio = (std::sqrt(30 * k - 5) - 1) / 4;
  return a0 * ratio * ratio;
}

Real membrane_hoop_stress(Real young, Real thickness, Real d0, Real eps_a, Real eps_v) {
  const Real hoop = std::sqrt((1 - eps_v) / (1 - eps_a)) - 1;
  return hoop > 0 ? 2 * young * thickness * hoop / d0 : 0;
}

io::SurfaceSnapshot membrane_surface(const Membrane& m) {
  auto nx = Kokkos::create_mirror_view_and_copy(HostSpace(), m.mesh.node_x);
  auto tri = Kokkos::create_mirror_view_and_copy(HostSpace(), m.mesh.tri);
  io::SurfaceSnapshot s;
  for (int k = 0; k < m.mesh.nnode; ++k)
    for (int d = 0; d < 3; ++d) s.nodes.push_back(nx(k, d));
  for (int t = 0; t < m.mesh.ntri; ++t)
    for (int d = 0; d < 3; ++d) s.triangles.push_back(tri(t, d));
  return s;
}

Real envelope_volume(const std::vector<Vec3>& centres, Real top, Real mean_radius, int slabs) {
  const Real dz = top / slabs;
  std::vector<std::vector<std::pair<Real, Real>>> xy(slabs);
  for (const Vec3& x : centres) xy[std::clamp(static_cast<int>(x.z / dz), 0, slabs - 1)].emplace_back(x.x, x.y);
  Real v = 0;
  for (auto& pts : xy) v += disc_hull_area(std::move(pts), mean_radius) * dz;
  return v;
}

Real envelope_volume(Simulation& sim, Real top, Real mean_radius, int slabs) {
  return envelope_volume(to_host_by_gid(sim.particles()).x, top, mean_radius, slabs);
}

int count_escaped(Simulation& sim, const Membrane& m, Real top) {
  auto nx = Kokkos::create_mirror_view_and_copy(HostSpace(), m.mesh.node_x);
  auto tri = Kokkos::create_mirror_view_and_copy(HostSpace(), m.mesh.tri);
  const HostParticles h = to_host_by_gid(sim.particles());
  int out = 0;
  for (const Vec3& x : h.x) {
    const Real rho = std::hypot(x.x, x.y);
    if (x.z < 0 || x.z > top || !(rho > 0)) {
      out += x.z < 0 || x.z > top;
      continue;
    }
    const Vec3 dir(x.x / rho, x.y / rho, 0);
    int crossings = 0;
    for (int t = 0; t < m.mesh.ntri; ++t)
      crossings += ray_crosses(x, dir, load(nx, tri(t, 0)), load(nx, tri(t, 1)), load(nx, tri(t, 2)));
    out += crossings % 2 == 0;
  }
  return out;
}

}  // namespace dem
