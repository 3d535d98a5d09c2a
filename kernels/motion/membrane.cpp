#include "kernels/motion/membrane.hpp"

#include <stdexcept>
#include <string>

#include "kernels/motion/integrate.hpp"  // damped: the same damping law as the balls
#include "kernels/core/reduce.hpp"

// Elasticity choice: total Lagrangian CST with the Green-Lagrange strain and a St. Venant-Kirchhoff
// plane-stress law, rather than a co-rotational small-strain CST, because
//  - the Green strain is built from edge dot products, which a rigid motion leaves unchanged, so the
//    forces are objective exactly (up to rounding) with no rotation to extract: no polar
//    decomposition, no element frame, no trigonometry, and no choice of in-plane frame to get wrong;
//  - the forces are the gradient of a strain energy, so elastic work is exact and a damped membrane
//    relaxes to a true minimum (a co-rotated CST is only approximately conservative);
//  - the strains of a triaxial membrane (hoop up to ~20 %, axial shortening ~15 %) are moderate:
//    Green and engineering strain differ by eps^2 / 2 there, and SVK's known softening in compression
//    only starts near 42 % shortening (the uniaxial force peaks at stretch 1/sqrt(3)).
// A membrane has no bending stiffness, so a compressed one does not buckle into wrinkles here; it
// carries the compressive stress, as the usual lab membrane correction (4 E t eps / D) assumes.

namespace dem {

namespace {

/// One thread per facet: forces on its three corners (N), from the terms switched on.
struct CornerForces {
  ConstVec3View x;
  Index3View tri;
  ConstVec3View G, Gi;
  ConstScalarView A0;
  Vec3View out;  ///< 3 ntri rows, corner 3 f + q
  Real young = 0, poisson = 0, thickness = 0;
  bool elastic = false;
  Real pressure = 0;
  bool contacts = false;
  ContactList c;
  ConstIndexView off;
  int first_object = 0;
  ConstVec3View bx;

  KOKKOS_INLINE_FUNCTION void operator()(const int f) const {
    const Vec3 a = load(x, tri(f, 0)), b = load(x, tri(f, 1)), cc = load(x, tri(f, 2));
    Vec3 fq[3];
    if (elastic) cst_forces(a, b, cc, load(G, f), load(Gi, f), A0(f), young, poisson, thickness, fq);
    if (pressure != Real(0)) {
      const Vec3 s = (-pressure / Real(3)) * area_vector(a, b, cc);
      for (int q = 0; q < 3; ++q) fq[q] += s;
    }
    if (contacts) {
      // This facet's contacts are contiguous in the key-sorted list; they are summed in key order.
      for (int k = off(first_object + f); k < off(first_object + f + 1); ++k) {
        const Vec3 fk = load(c.fc, k);
        if (norm2(fk) == Real(0)) continue;  // within the skin but not touching
        const FacetHit h = closest_on_triangle(load(bx, c.i(k)), a, b, cc);
        for (int q = 0; q < 3; ++q) fq[q] -= h.b[q] * fk;
      }
    }
    for (int q = 0; q < 3; ++q) store(out, 3 * f + q, fq[q]);
  }
};

/// One thread per node: the sum of its corners in ascending corner (= facet) order.
struct NodeGather {
  ConstVec3View corner_f;
  ConstIndexView off, corner;
  Vec3View out;

  KOKKOS_INLINE_FUNCTION void operator()(const int n) const {
    Vec3 s;
    for (int a = off(n); a < off(n + 1); ++a) s += load(corner_f, corner(a));
    store(out, n, s);
  }
};

/// Reference geometry of facet f from the current node_x: metric, its inverse, area.
struct ReferenceGeometry {
  ConstVec3View x;
  Index3View tri;
  Vec3View G, Gi;
  ScalarView A0;

  KOKKOS_INLINE_FUNCTION void operator()(const int f) const {
    const Vec3 a = load(x, tri(f, 0)), b = load(x, tri(f, 1)), c = load(x, tri(f, 2));
    const Vec3 g = edge_metric(a, b, c);
    // det G = |e1 x e2|^2: the cross product keeps its precision for slender triangles, where
    // G11 G22 - G12^2 would cancel.
    const Real det = norm2(cross(b - a, c - a));
    store(G, f, g);
    store(Gi, f, Vec3(g.z / det, -g.y / det, g.x / det));
    A0(f) = Real(0.5) * kc::sqrt(det);
  }
};

struct NodeLeapfrog {
  Vec3View x, v;
  ConstVec3View f;
  ConstScalarView mass;
  FlagView fixed;
  MembraneIntegrateParams prm;

  /// vals = {|F + m g| (free nodes), kinetic energy, non-finite flag, speed}.
  KOKKOS_INLINE_FUNCTION void operator()(const int n, Real* vals) const {
    const Real mn = mass(n);
    Vec3 vn = load(v, n);
    if (!fixed(n)) {
      const Vec3 F = load(f, n) + mn * prm.gravity;
      const Real a = prm.dt / (mn * prm.mass_scale);
      vn = vn + a * damped(F, vn, prm.alpha);
      store(v, n, vn);
      vals[0] = norm(F);
    }
    Vec3 xn = load(x, n);
    if (prm.move_nodes) {
      xn = xn + prm.dt * vn;
      store(x, n, xn);
    }
    vals[1] = Real(0.5) * mn * norm2(vn);
    const bool ok = kc::isfinite(xn.x) && kc::isfinite(xn.y) && kc::isfinite(xn.z) && kc::isfinite(vn.x) &&
                    kc::isfinite(vn.y) && kc::isfinite(vn.z);
    vals[2] = ok ? Real(0) : Real(1);
    vals[3] = norm(vn);
  }
};

/// Sums of the end rings' x and y (for their centroids).
struct RingSums {
  ConstVec3View x;
  ConstIndexView bottom, top;
  KOKKOS_INLINE_FUNCTION void operator()(const int k, Real* vals) const {
    if (k < int(bottom.extent(0))) { vals[0] = x(bottom(k), 0); vals[1] = x(bottom(k), 1); }
    if (k < int(top.extent(0))) { vals[2] = x(top(k), 0); vals[3] = x(top(k), 1); }
  }
};

/// Item i: lateral facet i, then the bottom cap's fan triangles, then the top cap's.
struct VolumeTerm {
  ConstVec3View x;
  Index3View tri;
  ConstIndexView bottom, top;
  Vec3 o, cb, ct;
  int ntri = 0;
  KOKKOS_INLINE_FUNCTION void operator()(const int i, Real* vals) const {
    const int nb = int(bottom.extent(0)), nt = int(top.extent(0));
    if (i < ntri) {
      vals[0] = signed_tet_volume(o, load(x, tri(i, 0)), load(x, tri(i, 1)), load(x, tri(i, 2)));
    } else if (i < ntri + nb) {
      const int k = i - ntri;
      vals[0] = signed_tet_volume(o, cb, load(x, bottom((k + 1) % nb)), load(x, bottom(k)));
    } else {
      const int k = i - ntri - nb;
      vals[0] = signed_tet_volume(o, ct, load(x, top(k)), load(x, top((k + 1) % nt)));
    }
  }
};

struct NodeMass {
  ConstScalarView mass;
  KOKKOS_INLINE_FUNCTION void operator()(const int n, Real* vals) const { vals[0] = mass(n); }
};

void fit(Vec3View& out, int n) {
  if (static_cast<int>(out.extent(0)) != n) out = Vec3View("dem::membrane::node_force", n);
}

IndexView to_device(const std::vector<int>& v, const char* label) {
  IndexView d(std::string(label), v.size());
  auto h = Kokkos::create_mirror_view(d);
  for (std::size_t k = 0; k < v.size(); ++k) h(k) = v[k];
  Kokkos::deep_copy(d, h);
  return d;
}

void check_material(const MembraneMaterial& mat) {
  auto bad = [](const std::string& what) { throw std::invalid_argument("build_membrane: " + what); };
  if (!(mat.young > 0)) bad("young must be > 0 Pa (got " + std::to_string(mat.young) + ")");
  if (!(mat.poisson > -1 && mat.poisson < 0.5))
    bad("poisson must lie in (-1, 0.5) (got " + std::to_string(mat.poisson) + ")");
  if (!(mat.thickness > 0)) bad("thickness must be > 0 m (got " + std::to_string(mat.thickness) + ")");
  if (!(mat.density > 0)) bad("density must be > 0 kg/m^3 (got " + std::to_string(mat.density) + ")");
}

/// Runs the corner pass with the given terms, then the node gather into out.
void node_forces(const Membrane& m, bool elastic, Real p, const FacetContacts* fc, Vec3View& out) {
  CornerForces k;
  k.x = m.mesh.node_x; k.tri = m.mesh.tri; k.G = m.ref_metric; k.Gi = m.ref_dual; k.A0 = m.ref_area;
  k.out = m.corner_f;
  k.young = m.mat.young; k.poisson = m.mat.poisson; k.thickness = m.mat.thickness;
  k.elastic = elastic;
  k.pressure = p;
  if (fc && fc->offsets.extent(0) > 0) {
    if (fc->first_object < 0 || static_cast<int>(fc->offsets.extent(0)) < fc->first_object + m.ntri + 1)
      throw std::invalid_argument("membrane forces: FacetContacts::offsets has " +
                                  std::to_string(fc->offsets.extent(0)) + " entries, needs first_object + ntri + 1 = " +
                                  std::to_string(fc->first_object + m.ntri + 1) + " (object_offsets(c, nwalls + ntri))");
    if (fc->c.n > 0 && fc->ball_x.extent(0) == 0)
      throw std::invalid_argument("membrane forces: FacetContacts::ball_x is empty but there are contacts");
    k.contacts = true;
    k.c = fc->c; k.off = fc->offsets; k.first_object = fc->first_object; k.bx = fc->ball_x;
  }
  Kokkos::parallel_for("dem::membrane::corner_forces", RangePolicy(0, m.ntri), k);
  fit(out, m.nnode);
  Kokkos::parallel_for("dem::membrane::node_gather", RangePolicy(0, m.nnode),
                       NodeGather{m.corner_f, m.corner_offset, m.corner, out});
}

}  // namespace

Membrane build_membrane(const FacetMesh& mesh, const std::vector<int>& bottom_ring, const std::vector<int>& top_ring,
                        const MembraneMaterial& mat) {
  check_material(mat);
  Membrane m;
  m.mesh = mesh;
  m.mat = mat;
  m.nnode = mesh.nnode;
  m.ntri = mesh.ntri;
  if (m.ntri <= 0) throw std::invalid_argument("build_membrane: the mesh has no facets");
  auto ht = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.tri);
  for (int f = 0; f < m.ntri; ++f) {
    for (int q = 0; q < 3; ++q)
      if (ht(f, q) < 0 || ht(f, q) >= m.nnode)
        throw std::invalid_argument("build_membrane: facet " + std::to_string(f) + " names node " +
                                    std::to_string(ht(f, q)) + ", outside [0, " + std::to_string(m.nnode) + ")");
  }
  for (const std::vector<int>* ring : {&bottom_ring, &top_ring})
    for (int n : *ring)
      if (n < 0 || n >= m.nnode)
        throw std::invalid_argument("build_membrane: end-ring node " + std::to_string(n) + " outside [0, " +
                                    std::to_string(m.nnode) + ")");

  m.ref_metric = Vec3View("dem::membrane::ref_metric", m.ntri);
  m.ref_dual = Vec3View("dem::membrane::ref_dual", m.ntri);
  m.ref_area = ScalarView("dem::membrane::ref_area", m.ntri);
  Kokkos::parallel_for("dem::membrane::reference", RangePolicy(0, m.ntri),
                       ReferenceGeometry{mesh.node_x, mesh.tri, m.ref_metric, m.ref_dual, m.ref_area});
  auto harea = Kokkos::create_mirror_view_and_copy(HostSpace(), m.ref_area);
  for (int f = 0; f < m.ntri; ++f)
    if (!(harea(f) > 0))
      throw std::invalid_argument("build_membrane: facet " + std::to_string(f) + " has zero area (degenerate)");

  // Node -> corner lists on the host, once: visiting facets in order makes every list ascending.
  std::vector<int> count(m.nnode + 1, 0);
  for (int f = 0; f < m.ntri; ++f)
    for (int q = 0; q < 3; ++q) ++count[ht(f, q) + 1];
  for (int n = 0; n < m.nnode; ++n) {
    if (count[n + 1] == 0)
      throw std::invalid_argument("build_membrane: node " + std::to_string(n) + " belongs to no facet (it would have no mass)");
    count[n + 1] += count[n];
  }
  std::vector<int> corner(3 * m.ntri), cursor(count.begin(), count.end() - 1);
  std::vector<Real> mass(m.nnode, 0);
  const Real per_area = mat.thickness * mat.density / 3;
  for (int f = 0; f < m.ntri; ++f)
    for (int q = 0; q < 3; ++q) corner[cursor[ht(f, q)]++] = 3 * f + q;
  for (int n = 0; n < m.nnode; ++n)
    for (int a = count[n]; a < count[n + 1]; ++a) mass[n] += per_area * harea(corner[a] / 3);
  m.corner_offset = to_device(count, "dem::membrane::corner_offset");
  m.corner = to_device(corner, "dem::membrane::corner");

  m.node_mass = ScalarView("dem::membrane::node_mass", m.nnode);
  m.fixed = FlagView("dem::membrane::fixed", m.nnode);
  auto hm = Kokkos::create_mirror_view(m.node_mass);
  auto hf = Kokkos::create_mirror_view(m.fixed);
  for (int n = 0; n < m.nnode; ++n) { hm(n) = mass[n]; hf(n) = 0; }
  for (const std::vector<int>* ring : {&bottom_ring, &top_ring})
    for (int n : *ring) hf(n) = 1;
  Kokkos::deep_copy(m.node_mass, hm);
  Kokkos::deep_copy(m.fixed, hf);
  m.ring_bottom = to_device(bottom_ring, "dem::membrane::ring_bottom");
  m.ring_top = to_device(top_ring, "dem::membrane::ring_top");
  m.corner_f = Vec3View("dem::membrane::corner_f", 3 * m.ntri);
  return m;
}

void membrane_internal_forces(const Membrane& m, Vec3View& out) { node_forces(m, true, 0, nullptr, out); }

void membrane_pressure_forces(const Membrane& m, Real p, Vec3View& out) {
  // p = 0 would switch every term off and gather zeros, which is also the right answer.
  node_forces(m, false, p, nullptr, out);
}

void membrane_contact_forces(const Membrane& m, const FacetContacts& fc, Vec3View& out) {
  node_forces(m, false, 0, &fc, out);
}

void membrane_forces(const Membrane& m, Real p, const FacetContacts& fc, Vec3View& out) {
  node_forces(m, true, p, &fc, out);
}

void membrane_integrate_to(Membrane& m, const Vec3View& force, const MembraneIntegrateParams& prm, Real* values) {
  if (static_cast<int>(force.extent(0)) != m.nnode)
    throw std::invalid_argument("membrane_integrate: force has " + std::to_string(force.extent(0)) +
                                " rows, the membrane " + std::to_string(m.nnode) + " nodes");
  const NodeLeapfrog lf{m.mesh.node_x, m.mesh.node_v, force, m.node_mass, m.fixed, prm};
  // Functors go in through a lambda: the reduction template then launches its
  // kernel on an extended-lambda closure type, which CUDA accepts in any translation unit.
  deterministic_reduce_to<3, 1>("dem::membrane::leapfrog", m.nnode, KOKKOS_LAMBDA(const int n, Real* v) { lf(n, v); },
                                values);
}

MembraneStepStats membrane_stats(const Real* values) {
  MembraneStepStats st;
  st.unbalanced = values[0];
  st.kinetic = values[1];
  st.finite = values[2] == 0;
  st.max_speed = values[3];
  return st;
}

MembraneStepStats membrane_integrate(Membrane& m, const Vec3View& force, const MembraneIntegrateParams& prm) {
  membrane_integrate_to(m, force, prm, reduce_root().data());
  Real values[kMembraneValues];
  read_root(values, kMembraneValues);
  return membrane_stats(values);
}

Real enclosed_volume(const Membrane& m, Real z_bottom, Real z_top) {
  const int nb = static_cast<int>(m.ring_bottom.extent(0)), nt = static_cast<int>(m.ring_top.extent(0));
  if (nb < 3 || nt < 3)
    throw std::invalid_argument("enclosed_volume: the membrane needs a bottom and a top end ring of >= 3 nodes (has " +
                                std::to_string(nb) + " and " + std::to_string(nt) + ")");
  Real c[4];
  const RingSums rs{m.mesh.node_x, m.ring_bottom, m.ring_top};
  deterministic_reduce<4, 0>("dem::membrane::ring_centroids", nb > nt ? nb : nt,
                             KOKKOS_LAMBDA(const int k, Real* v) { rs(k, v); }, c);
  VolumeTerm t;
  t.x = m.mesh.node_x; t.tri = m.mesh.tri; t.bottom = m.ring_bottom; t.top = m.ring_top; t.ntri = m.ntri;
  t.cb = Vec3(c[0] / nb, c[1] / nb, z_bottom);
  t.ct = Vec3(c[2] / nt, c[3] / nt, z_top);
  // Any origin gives the same volume for a closed surface; one on the axis at mid-height keeps the
  // tetrahedra small, so their rounding is small.
  t.o = Real(0.5) * (t.cb + t.ct);
  Real v[1];
  deterministic_reduce<1, 0>("dem::membrane::volume", m.ntri + nb + nt, KOKKOS_LAMBDA(const int i, Real* s) { t(i, s); },
                             v);
  return v[0];
}

Real membrane_mass(const Membrane& m) {
  Real s[1];
  const NodeMass nm{m.node_mass};
  deterministic_reduce<1, 0>("dem::membrane::mass", m.nnode, KOKKOS_LAMBDA(const int n, Real* v) { nm(n, v); }, s);
  return s[0];
}

}  // namespace dem
