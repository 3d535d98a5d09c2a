#include "contact_force.hpp"

#include "contact_detect.hpp"

namespace dem {

namespace {

struct MaxOverlap {
  using value_type = OverlapStat;
  KOKKOS_INLINE_FUNCTION void join(volatile value_type& a, const volatile value_type& b) const {
    if (b.ratio > a.ratio || (b.ratio == a.ratio && b.contact > a.contact)) { a.ratio = b.ratio; a.contact = b.contact; }
  }
  KOKKOS_INLINE_FUNCTION void join(value_type& a, const value_type& b) const {
    if (b.ratio > a.ratio || (b.ratio == a.ratio && b.contact > a.contact)) a = b;
  }
  KOKKOS_INLINE_FUNCTION void init(value_type& a) const { a.ratio = 0; a.contact = -1; }
};

struct BallForce : MaxOverlap {
  ConstVec3View x, v, w;
  ConstScalarView radius, mass;
  ConstIndexView material;
  ContactList c;
  ParamTableView params;
  Domain dom;
  Real dt;

  KOKKOS_INLINE_FUNCTION void operator()(const int s, value_type& worst) const {
    const int i = c.i(s), j = c.j(s);
    const Vec3 d = dom.min_image(load(x, j) - load(x, i));
    const Real dist = norm(d);
    const Real ri = radius(i), rj = radius(j);
    const Real overlap = ri + rj - dist;
    if (overlap <= 0 || dist == Real(0)) { open_contact(c, s); return; }
    ContactKinematics k;
    k.n = (Real(1) / dist) * d;
    k.overlap = overlap;
    k.r1 = ri; k.r2 = rj;
    k.mc = mass(i) * mass(j) / (mass(i) + mass(j));
    const Vec3 r1 = (ri - Real(0.5) * overlap) * k.n;
    const Vec3 r2 = r1 - d;
    const Vec3 wi = load(w, i), wj = load(w, j);
    k.vrel = (load(v, j) + cross(wj, r2)) - (load(v, i) + cross(wi, r1));
    k.dtheta = dt * (wj - wi);
    k.dt = dt;
    const ContactParams& prm = params(material(i), material(j));
    k.kn = RRLinear::stiffness(prm, ri, rj);
    apply_law(c, s, prm, k, r1, r2);
    const value_type mine{overlap / kc::min(ri, rj), s};
    join(worst, mine);
  }
};

struct WallForce : MaxOverlap {
  ConstVec3View x, v, w;
  ConstScalarView radius, mass;
  ConstIndexView material;
  ContactList c;
  IndexView adj_off, adj_entry;
  WallSet walls;
  FacetMesh mesh;
  ParamTableView params;
  Real dt;

  /// True when facet f's edge/vertex hit must yield to another touching facet of ball i.
  KOKKOS_INLINE_FUNCTION bool yields(int i, int f, const FacetHit& hit, Real dist, const Vec3& xi) const {
    const int t[3] = {mesh.tri(f, 0), mesh.tri(f, 1), mesh.tri(f, 2)};
    int nodes[2];
    feature_nodes(hit, t, nodes);
    const Real eps = Real(1e-12) * radius(i);
    for (int a = adj_off(i); a < adj_off(i + 1); ++a) {
      const int g = c.j(adj_entry(a) >> 1) - walls.n;
      if (g < 0 || g == f) continue;
      bool shares = true;
      for (int q = 0; q < 2; ++q) {
        if (nodes[q] < 0) continue;
        shares = shares && (mesh.tri(g, 0) == nodes[q] || mesh.tri(g, 1) == nodes[q] || mesh.tri(g, 2) == nodes[q]);
      }
      if (!shares) continue;
      const FacetHit other = facet_hit(mesh, g, xi);
      const Real dg = norm(other.cp - xi);
      if (dg >= radius(i)) continue;
      if (other.feature == kFace ? dg <= dist + eps : (dg < dist - eps || (dg <= dist + eps && g < f))) return true;
    }
    return false;
  }

  KOKKOS_INLINE_FUNCTION void operator()(const int s, value_type& worst) const {
    const int i = c.i(s), obj = c.j(s);
    const Vec3 xi = load(x, i);
    const Real ri = radius(i);
    ContactKinematics k;
    Real dist;
    Vec3 vwall;
    int wmat;
    if (obj < walls.n) {
      Vec3 cp;
      if (!wall_contact(walls.kind(obj), load(walls.point, obj), load(walls.normal, obj), walls.radius(obj), xi, k.n,
                        dist, cp)) { open_contact(c, s); return; }
      vwall = load(walls.velocity, obj);
      wmat = walls.material(obj);
    } else {
      const int f = obj - walls.n;
      const FacetHit hit = facet_hit(mesh, f, xi);
      const Vec3 d = hit.cp - xi;
      dist = norm(d);
      if (dist >= ri || dist == Real(0) || (hit.feature != kFace && yields(i, f, hit, dist, xi))) {
        open_contact(c, s);
        return;
      }
      k.n = (Real(1) / dist) * d;
      vwall = Vec3();
      for (int q = 0; q < 3; ++q) vwall += hit.b[q] * load(mesh.node_v, mesh.tri(f, q));
      wmat = mesh.material;
    }
    const Real overlap = ri - dist;
    if (overlap <= 0) { open_contact(c, s); return; }
    k.overlap = overlap;
    k.r1 = ri; k.r2 = 0;
    k.mc = mass(i);
    const Vec3 r1 = (ri - Real(0.5) * overlap) * k.n;
    const Vec3 wi = load(w, i);
    k.vrel = vwall - (load(v, i) + cross(wi, r1));
    k.dtheta = -dt * wi;
    k.dt = dt;
    const ContactParams& prm = params(material(i), wmat);
    k.kn = RRLinear::stiffness(prm, ri, 0);
    apply_law(c, s, prm, k, r1, Vec3());
    const value_type mine{overlap / ri, s};
    join(worst, mine);
  }
};

template <class Kernel>
void bind_particles(Kernel& k, const Particles& p) {
  k.x = p.x; k.v = p.v; k.w = p.w; k.radius = p.radius; k.mass = p.mass; k.material = p.material;
}

}  // namespace

OverlapStat compute_ball_forces(const Particles& p, ContactList& c, const ParamTableView& params, const Domain& dom,
                                Real dt) {
  BallForce k;
  bind_particles(k, p);
  k.c = c; k.params = params; k.dom = dom; k.dt = dt;
  OverlapStat worst;
  Kokkos::parallel_reduce("dem::force::balls", RangePolicy(0, c.n), k, worst);
  return worst;
}

OverlapStat compute_wall_forces(const Particles& p, ContactList& c, const Adjacency& adj, const WallSet& walls,
                                const FacetMesh& mesh, const ParamTableView& params, Real dt) {
  WallForce k;
  bind_particles(k, p);
  k.c = c; k.adj_off = adj.offset; k.adj_entry = adj.entry; k.walls = walls; k.mesh = mesh;
  k.params = params; k.dt = dt;
  OverlapStat worst;
  Kokkos::parallel_reduce("dem::force::walls", RangePolicy(0, c.n), k, worst);
  return worst;
}

}  // namespace dem
