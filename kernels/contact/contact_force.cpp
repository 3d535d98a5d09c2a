#include "kernels/contact/contact_force.hpp"

#include <algorithm>

#include "kernels/neighbor/contact_detect.hpp"

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

/// A force kernel K's items, one to a thread of a team: on a GPU the kernels run as teams (launch_forces).
template <class K>
struct ItemsInTeams : MaxOverlap {
  K k;
  int items;
  KOKKOS_INLINE_FUNCTION void operator()(const Kokkos::TeamPolicy<ExecSpace>::member_type& m, value_type& worst) const {
    const int item = m.league_rank() * m.team_size() + m.team_rank();
    if (item < items) k(item, worst);
  }
};

/// Launches force kernel `k` over its `items`, the largest overlap into `worst` on the device. On CUDA Kokkos 3.4
/// launches a RangePolicy reduction on at most as many blocks as a block has threads: the ball forces ran on 256
/// blocks of 256 threads for 3 million contacts (ncu, fifth device run), at a third of the H200's bandwidth, too
/// few threads in flight to hide the gathers' latency. As a TeamPolicy reduction (a shuffle reduction: up to 32,768
/// blocks) each item has a thread of its own. The largest overlap and its tie rule (MaxOverlap::join) are the same
/// in any order and for any number of contributions, so the result is the RangePolicy's.
template <class K>
void launch_forces(const char* label, const K& k, int items, const OverlapResultView& worst) {
  if constexpr (kOnDevice) {
    using Teams = Kokkos::TeamPolicy<ExecSpace>;
    const ItemsInTeams<K> f{{}, k, items};
    // The team size depends on the kernel's type alone: found once, not at every step.
    static const int size = Teams(1, 1).team_size_recommended(f, Kokkos::ParallelReduceTag());
    Kokkos::parallel_reduce(label, Teams(std::max(1, (items + size - 1) / size), size), f, worst);
  } else {
    Kokkos::parallel_reduce(label, RangePolicy(0, items), k, worst);
  }
}

/// One work item per kContactLanes consecutive ball-ball contacts, evaluated side by side as lanes of T. Each
/// lane's arithmetic is that of a single contact, so the results do not depend on which lane a contact falls in.
struct BallForce : MaxOverlap {
  using T = ContactPack;
  static constexpr int W = kContactLanes;
  ConstVec3View x, v, w;
  ConstScalarView radius, mass;
  ConstIndexView material;
  ContactList c;
  ParamTableView params;
  SpecimenTable spec;
  ContactItems items;

  KOKKOS_INLINE_FUNCTION void operator()(const int item, value_type& worst) const {
    int sp = 0, s0 = item * W, end = c.n;
    if (items.specimens > 0) {  // the specimen whose items hold this one: the last to start at or before it
      int lo = 0, hi = items.specimens - 1;
      while (lo < hi) {
        const int mid = (lo + hi + 1) / 2;
        if (items.item_first(mid) <= item) lo = mid; else hi = mid - 1;
      }
      sp = lo;
      s0 = items.contact_first(sp) + (item - items.item_first(sp)) * W;
      end = items.contact_first(sp + 1);
    }
    const int lanes = end - s0 < W ? end - s0 : W;
    const SpecimenParams& specimen = spec(sp);
    const Domain& dom = spec.dom(sp);
    const MinImage image(dom);
    const Real dt = specimen.integ.dt;
    const int row = specimen.material_row;
    // Lanes past the end repeat the last contact; their results are not stored.
    int cs[W], ci[W], cj[W];
    const ContactParams* pair[W];
    bool one_pair = true;
    TRIAXDEM_UNROLL_LANES
    for (int k = 0; k < W; ++k) {
      cs[k] = s0 + (k < lanes ? k : lanes - 1);
      ci[k] = c.i(cs[k]);
      cj[k] = c.j(cs[k]);
      pair[k] = &params(row + material(ci[k]), material(cj[k]));
      one_pair = one_pair && pair[k] == pair[0];
    }
    const Vec3T<T> d = image(vec_of_lanes<T>([&](int k) { return load(x, cj[k]); }) -
                             vec_of_lanes<T>([&](int k) { return load(x, ci[k]); }));
    const Vec3T<T> vi = vec_of_lanes<T>([&](int k) { return load(v, ci[k]); });
    const Vec3T<T> vj = vec_of_lanes<T>([&](int k) { return load(v, cj[k]); });
    const Vec3T<T> wi = vec_of_lanes<T>([&](int k) { return load(w, ci[k]); });
    const Vec3T<T> wj = vec_of_lanes<T>([&](int k) { return load(w, cj[k]); });
    const T ri = from_lanes<T>([&](int k) { return radius(ci[k]); });
    const T rj = from_lanes<T>([&](int k) { return radius(cj[k]); });
    const ContactParamsT<T> prm = one_pair ? params_of_lanes<T>([&](int) -> const ContactParams& { return *pair[0]; })
                                           : params_of_lanes<T>([&](int k) -> const ContactParams& { return *pair[k]; });
    const T dist = norm(d);
    const T overlap = ri + rj - dist;
    const auto touching = !((overlap <= T(0)) | (dist == T(0)));
    if (!any(touching)) {
      for (int k = 0; k < lanes; ++k) open_contact(c, s0 + k);
      return;
    }
    ContactKinematicsT<T> kin;
    kin.n = (T(1) / dist) * d;
    kin.overlap = overlap;
    kin.r1 = ri; kin.r2 = rj;
    kin.m1 = from_lanes<T>([&](int k) { return mass(ci[k]); });
    kin.m2 = from_lanes<T>([&](int k) { return mass(cj[k]); });
    // Branch vectors from the centres to the contact point: r1 = a n, r2 = -b n (both along n),
    // which folds the two spin terms of the relative velocity into one cross product.
    const T a = ri - Real(0.5) * overlap, b = rj - Real(0.5) * overlap;
    kin.vrel = vj - vi - cross(a * wi + b * wj, kin.n) + dom.affine_velocity(d);
    kin.dtheta = dt * (wj - wi);
    kin.dt = dt;
    kin.kn = ContactLaws::stiffness(prm, ri, rj);
    ContactHistoryT<T> h;  // flags start clear: the law sets or clears every ContactFlag bit of a touching contact
    const bool full = lanes == W;
    h.fs = load_lanes<T>(c.fs, s0, cs, full);
    h.mr = load_lanes<T>(c.mr, s0, cs, full);
    // Only the slots the pack's parameters use are read or changed: the others stay as stored.
    const unsigned slots = ContactLaws::slots(prm);
    for (int q = 0; q < kHistorySlots; ++q)
      if (slots & (1u << q)) h.slot[q] = from_lanes<T>([&](int k) { return c.slot[q](cs[k]); });
    const ContactOutputT<T> out = ContactLaws::eval(prm, kin, h);
    const Vec3T<T> nxf = cross(kin.n, out.force);
    const Vec3T<T> mt = b * nxf - out.moment, mo = a * nxf + out.moment;
    const auto store_results = [&](auto at) {
      store_law(c, at, h, out, slots);
      put(c.mo, at, mo);
      put(c.mt, at, mt);
    };
    if (full && all(touching)) {
      store_results(PackRows{s0});
    } else {
      TRIAXDEM_UNROLL_LANES
      for (int k = 0; k < W; ++k) {
        if (k == lanes) break;
        if (lane(touching, k)) store_results(LaneRow{s0 + k, k});
        else open_contact(c, s0 + k);
      }
    }
    // A pack whose largest ratio is below the worst so far cannot change it (ties go to the later contact).
    const T ratio = select(touching, overlap / kc::min(ri, rj), T(0));
    if (items.specimens > 0 && max_lane(ratio) > specimen.overlap_limit) {
      TRIAXDEM_UNROLL_LANES
      for (int k = 0; k < W; ++k) {
        if (k == lanes) break;
        if (!lane(touching, k) || !(lane(ratio, k) > specimen.overlap_limit)) continue;
        items.exceeded(Kokkos::atomic_fetch_add(&items.exceeded_count(), 1)) = value_type{lane(ratio, k), s0 + k};
      }
    }
    if (max_lane(ratio) < worst.ratio) return;
    TRIAXDEM_UNROLL_LANES
    for (int k = 0; k < W; ++k) {
      if (k == lanes) break;
      if (!lane(touching, k)) continue;
      const value_type mine{lane(ratio, k), s0 + k};
      join(worst, mine);
    }
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
    k.kn = ContactLaws::stiffness(prm, ri, 0);
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

/// The largest overlap of a force kernel's contacts, returned to the host.
template <class Launch>
OverlapStat read_back(const Launch& launch) {
  const OverlapRowsView worst("dem::force::worst", 1);
  const OverlapResultView result(Kokkos::subview(worst, 0, 0).data());  // the host may not index device memory
  launch(result);
  OverlapStat h;
  Kokkos::deep_copy(h, result);
  return h;
}

}  // namespace

void compute_ball_forces(const Particles& p, ContactList& c, const ParamTableView& params, const Domain& dom, Real dt,
                         const OverlapResultView& worst) {
  SpecimenTable one;
  one.one.dom = dom;
  one.one.integ.dt = dt;
  compute_ball_forces(p, c, params, one, worst);
}

void compute_ball_forces(const Particles& p, ContactList& c, const ParamTableView& params, const SpecimenTable& one,
                         const OverlapResultView& worst) {
  BallForce k;
  bind_particles(k, p);
  k.c = c; k.params = params; k.spec = one;
  const int items = (c.n + BallForce::W - 1) / BallForce::W;
  launch_forces("dem::force::balls" TRIAXDEM_DEVICE_RESULT, k, items, worst);
}

void compute_ball_forces(const Particles& p, ContactList& c, const ParamTableView& params,
                         const SpecimenParamsView& specimens, const ContactItems& items,
                         const OverlapResultView& worst) {
  BallForce k;
  bind_particles(k, p);
  k.c = c; k.params = params; k.spec.many = specimens; k.items = items;
  launch_forces("dem::force::balls" TRIAXDEM_DEVICE_RESULT, k, items.items, worst);
}

OverlapStat compute_ball_forces(const Particles& p, ContactList& c, const ParamTableView& params, const Domain& dom,
                                Real dt) {
  return read_back([&](const OverlapResultView& w) { compute_ball_forces(p, c, params, dom, dt, w); });
}

void compute_wall_forces(const Particles& p, ContactList& c, const Adjacency& adj, const WallSet& walls,
                         const FacetMesh& mesh, const ParamTableView& params, Real dt, const OverlapResultView& worst) {
  WallForce k;
  bind_particles(k, p);
  k.c = c; k.adj_off = adj.offset; k.adj_entry = adj.entry; k.walls = walls; k.mesh = mesh;
  k.params = params; k.dt = dt;
  launch_forces("dem::force::walls" TRIAXDEM_DEVICE_RESULT, k, c.n, worst);
}

OverlapStat compute_wall_forces(const Particles& p, ContactList& c, const Adjacency& adj, const WallSet& walls,
                                const FacetMesh& mesh, const ParamTableView& params, Real dt) {
  return read_back([&](const OverlapResultView& w) { compute_wall_forces(p, c, adj, walls, mesh, params, dt, w); });
}

}  // namespace dem
