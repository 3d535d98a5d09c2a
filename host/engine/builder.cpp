#include "host/engine/builder.hpp"

#include <algorithm>
#include <cmath>
#include <tuple>

namespace dem {

Real solid_volume(const std::vector<BallSpec>& balls) {
  Real v = 0;
  for (const BallSpec& b : balls) v += 4.0 / 3.0 * M_PI * b.radius * b.radius * b.radius;
  return v;
}

Particles make_particles(const std::vector<BallSpec>& balls) {
  Particles p(static_cast<int>(balls.size()));
  auto x = Kokkos::create_mirror_view(p.x), v = Kokkos::create_mirror_view(p.v), w = Kokkos::create_mirror_view(p.w);
  auto r = Kokkos::create_mirror_view(p.radius), m = Kokkos::create_mirror_view(p.mass);
  auto in = Kokkos::create_mirror_view(p.inertia);
  auto gid = Kokkos::create_mirror_view(p.gid);
  auto spec = Kokkos::create_mirror_view(p.specimen), mat = Kokkos::create_mirror_view(p.material);
  for (int i = 0; i < p.n; ++i) {
    const BallSpec& b = balls[i];
    store(x, i, b.x);
    store(v, i, b.v);
    store(w, i, b.w);
    r(i) = b.radius;
    m(i) = b.density * 4.0 / 3.0 * M_PI * b.radius * b.radius * b.radius;
    in(i) = 0.4 * m(i) * b.radius * b.radius;
    gid(i) = static_cast<std::uint32_t>(i);
    spec(i) = b.specimen;
    mat(i) = b.material;
  }
  Kokkos::deep_copy(p.x, x); Kokkos::deep_copy(p.v, v); Kokkos::deep_copy(p.w, w);
  Kokkos::deep_copy(p.radius, r); Kokkos::deep_copy(p.mass, m); Kokkos::deep_copy(p.inertia, in);
  Kokkos::deep_copy(p.gid, gid); Kokkos::deep_copy(p.specimen, spec); Kokkos::deep_copy(p.material, mat);
  Kokkos::deep_copy(p.x_ref, p.x);
  return p;
}

void sort_like_cells(std::vector<BallSpec>& balls, Real cell) {
  if (balls.empty()) return;
  Vec3 lo = balls[0].x;
  for (const BallSpec& b : balls) lo = Vec3(std::min(lo.x, b.x.x), std::min(lo.y, b.x.y), std::min(lo.z, b.x.z));
  auto key = [&](const BallSpec& b) {
    return std::make_tuple(std::floor((b.x.z - lo.z) / cell), std::floor((b.x.y - lo.y) / cell), b.x.x);
  };
  std::stable_sort(balls.begin(), balls.end(), [&](const BallSpec& a, const BallSpec& b) { return key(a) < key(b); });
}

WallSet make_walls(const std::vector<WallSpec>& walls) {
  WallSet s(static_cast<int>(walls.size()));
  auto kind = Kokkos::create_mirror_view(s.kind), mat = Kokkos::create_mirror_view(s.material);
  auto pt = Kokkos::create_mirror_view(s.point), nr = Kokkos::create_mirror_view(s.normal);
  auto vel = Kokkos::create_mirror_view(s.velocity);
  auto rad = Kokkos::create_mirror_view(s.radius);
  for (int k = 0; k < s.n; ++k) {
    kind(k) = walls[k].kind;
    store(pt, k, walls[k].point);
    store(nr, k, (1.0 / norm(walls[k].normal)) * walls[k].normal);
    store(vel, k, walls[k].velocity);
    rad(k) = walls[k].radius;
    mat(k) = walls[k].material;
  }
  Kokkos::deep_copy(s.kind, kind); Kokkos::deep_copy(s.material, mat); Kokkos::deep_copy(s.point, pt);
  Kokkos::deep_copy(s.normal, nr); Kokkos::deep_copy(s.velocity, vel); Kokkos::deep_copy(s.radius, rad);
  return s;
}

FacetMesh make_mesh(const std::vector<Real>& nodes, const std::vector<int>& tris, int material) {
  FacetMesh m(static_cast<int>(nodes.size() / 3), static_cast<int>(tris.size() / 3));
  m.material = material;
  auto hx = Kokkos::create_mirror_view(m.node_x);
  auto ht = Kokkos::create_mirror_view(m.tri);
  for (int k = 0; k < m.nnode; ++k)
    for (int d = 0; d < 3; ++d) hx(k, d) = nodes[3 * k + d];
  for (int t = 0; t < m.ntri; ++t)
    for (int d = 0; d < 3; ++d) ht(t, d) = tris[3 * t + d];
  Kokkos::deep_copy(m.node_x, hx);
  Kokkos::deep_copy(m.tri, ht);
  return m;
}

HostParticles to_host_by_gid(const Particles& p) {
  auto gid = Kokkos::create_mirror_view_and_copy(HostSpace(), p.gid);
  const Vec3View* src[3] = {&p.x, &p.v, &p.w};
  HostParticles out;
  std::vector<Vec3>* dst[3] = {&out.x, &out.v, &out.w};
  for (int q = 0; q < 3; ++q) {
    auto h = Kokkos::create_mirror_view_and_copy(HostSpace(), *src[q]);
    dst[q]->resize(p.n);
    for (int i = 0; i < p.n; ++i) (*dst[q])[gid(i)] = load(h, i);
  }
  return out;
}

}  // namespace dem
