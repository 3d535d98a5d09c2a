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

/// One thread per particle: evaluates the contacts it owns, sums its own side in key order.
struct BallForce : MaxOverlap {
  ConstVec3View x, v, w;
  Vec3View f, m;
  ConstScalarView radius, mass;
  ConstIndexView material;
  ContactList c;
  Index2View own;
  ParamTableView params;
  Domain dom;
  MinImage image;
  Real dt;

  KOKKOS_INLINE_FUNCTION void operator()(const int i, value_type& worst) const {
    const Vec3 xi = load(x, i), vi = load(v, i), wi = load(w, i);
    const Real ri = radius(i);
    Vec3 fi, mi;
    for (int s = own(i, 0); s < own(i, 1); ++s) {
      const int j = c.j(s);
      const Vec3 d = image(load(x, j) - xi);
      const Real dist = norm(d);
      const Real rj = radius(j);
      const Real overlap = ri + rj - dist;
      if (overlap <= 0 || dist == Real(0)) { open_contact(c, s); continue; }
      ContactKinematics k;
      k.n = (Real(1) / dist) * d;
      k.overlap = overlap;
      k.r1 = ri; k.r2 = rj;
      k.m1 = mass(i);
      k.m2 = mass(j);
      // Branch vectors from the centres to the contact point: r1 = a n, r2 = -b n (both along n),
      // which folds the two spin terms of the relative velocity into one cross product.
      const Real a = ri - Real(0.5) * overlap, b = rj - Real(0.5) * overlap;
      const Vec3 wj = load(w, j);
      k.vrel = load(v, j) - vi - cross(a * wi + b * wj, k.n) + dom.affine_velocity(d);
      k.dtheta = dt * (wj - wi);
      k.dt = dt;
      const ContactParams& prm = params(material(i), material(j));
      k.kn = RRLinear::stiffness(prm, ri, rj);
      const ContactOutput out = apply_law(c, s, prm, k);
      const Vec3 nxf = cross(k.n, out.force);
      store(c.mt, s, b * nxf - out.moment);
      fi += out.force;
      mi += a * nxf + out.moment;
      const value_type mine{overlap / kc::min(ri, rj), s};
      join(worst, mine);
    }
    store(f, i, fi);
    store(m, i, mi);
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
      const int g = c.j(adj_entry(a)) - walls.n;
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
    k.m1 = mass(i);
    k.m2 = 0;
    const Vec3 r1 = (ri - Real(0.5) * overlap) * k.n;
    const Vec3 wi = load(w, i);
    k.vrel = vwall - (load(v, i) + cross(wi, r1));
    k.dtheta = -dt * wi;
    k.dt = dt;
    const ContactParams& prm = params(material(i), wmat);
    k.kn = RRLinear::stiffness(prm, ri, 0);
    const ContactOutput out = apply_law(c, s, prm, k);
    store(c.mt, s, cross(r1, out.force) + out.moment);
    const value_type mine{overlap / ri, s};
    join(worst, mine);
  }
};

template <class Kernel>
void bind_particles(Kernel& k, const Particles& p) {
  k.x = p.x; k.v = p.v; k.w = p.w; k.radius = p.radius; k.mass = p.mass; k.material = p.material;
}

}  // namespace

OverlapStat compute_ball_forces(Particles& p, ContactList& c, const Index2View& own, const ParamTableView& params,
                                const Domain& dom, Real dt) {
  BallForce k;
  bind_particles(k, p);
  k.f = p.f; k.m = p.m;
  k.c = c; k.own = own; k.params = params; k.dom = dom; k.image = MinImage(dom); k.dt = dt;
  OverlapStat worst;
  Kokkos::parallel_reduce("dem::force::balls", RangePolicy(0, p.n), k, worst);
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
