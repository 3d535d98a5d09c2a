#pragma once
/// Flexible membrane of the triaxial test: a triangulated surface (the same FacetMesh the balls touch)
/// whose nodes carry mass and are loaded by
///   - in-plane elasticity: constant-strain triangles (CST), plane stress, St. Venant-Kirchhoff law on
///     the Green-Lagrange strain, total Lagrangian (see membrane.cpp for why);
///   - the cell pressure as a follower load, -p S_f / 3 on each vertex of facet f;
///   - the reactions of the ball-facet contacts, split with the barycentric weights of the contact point.
/// Every per-node sum is a gather over a node -> corner list sorted by corner, built once (the topology
/// never changes), so node forces are bit-for-bit the same for any thread count.
#include <vector>

#include "kernels/neighbor/contact_list.hpp"
#include "kernels/core/vec3.hpp"
#include "kernels/core/walls.hpp"

namespace dem {

/// Membrane material and geometry. Defaults: latex, 0.5 mm, as in Tang et al. (2025).
struct MembraneMaterial {
  Real young = 1.4e6;      ///< in-plane Young's modulus E_m (Pa)
  Real poisson = 0.49;     ///< in-plane Poisson's ratio (plane stress: any value in (-1, 0.5))
  Real thickness = 0.5e-3; ///< t (m)
  Real density = 930;      ///< kg/m^3 (node masses only)
};

/// Device state of a membrane. Views are shared handles: `mesh` can be handed to the Simulation as
/// its facet walls and both see the same node positions and velocities.
struct Membrane {
  FacetMesh mesh;          ///< node_x (m), node_v (m/s), tri (counter-clockwise seen from outside)
  ScalarView node_mass;    ///< lumped mass (kg): t rho A0 / 3 from every adjacent facet
  FlagView fixed;          ///< 1: kinematically prescribed node (end rings tied to the platens)
  Vec3View ref_metric;     ///< per facet: reference metric (G11, G12, G22) of edges e1 = b - a, e2 = c - a (m^2)
  Vec3View ref_dual;       ///< per facet: its inverse (G^11, G^12, G^22) (1/m^2)
  ScalarView ref_area;     ///< per facet: reference area A0 (m^2)
  IndexView corner_offset; ///< node -> corner CSR offsets (nnode + 1)
  IndexView corner;        ///< corner = 3 f + q (vertex q of facet f), ascending within each node
  IndexView ring_bottom;   ///< bottom end-ring nodes, in the order that closes the surface (see enclosed_volume)
  IndexView ring_top;      ///< top end-ring nodes, same
  Vec3View corner_f;       ///< scratch (N): per-corner force before the node gather, 3 ntri rows
  MembraneMaterial mat;
  int nnode = 0, ntri = 0;
};

/// Builds a membrane whose reference (stress-free) state is the mesh's current node_x. End-ring
/// nodes are marked fixed. Ring order: the bottom ring must run along its lateral facets' edges in
/// the direction those facets traverse them (for a cylinder with outward normals: increasing angle
/// seen from +z); the top ring likewise, i.e. the caps (centre, r[k+1], r[k]) at the bottom and
/// (centre, r[k], r[k+1]) at the top continue the lateral orientation. Rings may be empty (a patch).
/// Throws std::invalid_argument for a bad material, a node index out of range or a degenerate facet.
Membrane build_membrane(const FacetMesh& mesh, const std::vector<int>& bottom_ring, const std::vector<int>& top_ring,
                        const MembraneMaterial& mat);

/// The ball-facet contacts the membrane reacts to.
struct FacetContacts {
  ContactList c;           ///< ball-wall contacts, key-sorted (object = first_object + facet)
  IndexView offsets;       ///< object_offsets(c, first_object + ntri): each object's contact range
  int first_object = 0;    ///< object number of facet 0 (the number of analytic walls)
  ConstVec3View ball_x;    ///< particle positions (m), indexed by c.i
};

/// Elastic (CST) node forces (N). `out` is resized to nnode rows when needed and overwritten.
void membrane_internal_forces(const Membrane& m, Vec3View& out);
/// Follower pressure load (N): -p/3 sum over adjacent facets of the current area vector (outward).
/// p > 0 (Pa) pushes the membrane towards the axis (cell pressure).
void membrane_pressure_forces(const Membrane& m, Real p, Vec3View& out);
/// Reactions of the ball-facet contacts (N): -fc(k) of each contact on facet f, split over f's nodes
/// with the barycentric weights of the point of f closest to the ball centre (recomputed here from
/// ball_x and node_x: call it before either moves, i.e. between the force pass and integration).
void membrane_contact_forces(const Membrane& m, const FacetContacts& fc, Vec3View& out);
/// All three in one pass (the time loop's call); per corner: elastic + pressure + contacts, then the gather.
/// A FacetContacts with an empty `offsets` View means no contacts. Fixed nodes get their forces too:
/// minus their sum is what the platens carry through the tied rings (for the axial force balance).
void membrane_forces(const Membrane& m, Real p, const FacetContacts& fc, Vec3View& out);

/// Node integration parameters (same scheme as kernels/motion/integrate.hpp).
struct MembraneIntegrateParams {
  Vec3 gravity;            ///< m/s^2 (usually zero: the membrane's weight is negligible)
  Real alpha = 0.7;        ///< local damping coefficient
  Real mass_scale = 1.0;   ///< node mass scaling for the time step (1 = physical)
  Real dt = 0;             ///< s
  /// Advance node_x by dt node_v here. Set false when the Simulation moves its facet mesh itself
  /// (Simulation::move_boundaries already does x += dt v for every node).
  bool move_nodes = true;
};

struct MembraneStepStats {
  Real unbalanced = 0;     ///< sum over free nodes of |F + m g| before damping (N)
  Real kinetic = 0;        ///< sum of 1/2 m v^2 over all nodes at t + dt/2 (J), physical mass
  Real max_speed = 0;      ///< largest node speed (m/s), fixed nodes included
  bool finite = true;      ///< false when a node position or velocity is not finite
};

/// Centred differences with local damping for free nodes; fixed nodes keep the velocity the caller
/// set in node_v (the platen's). Forces in `force` (N, per node), e.g. from membrane_forces.
MembraneStepStats membrane_integrate(Membrane& m, const Vec3View& force, const MembraneIntegrateParams& prm);
/// The same, with the step's kMembraneValues values left in device memory at `values` (membrane_stats reads them).
constexpr int kMembraneValues = 4;
void membrane_integrate_to(Membrane& m, const Vec3View& force, const MembraneIntegrateParams& prm, Real* values);
MembraneStepStats membrane_stats(const Real* values);

/// Volume (m^3) enclosed by the membrane and the two platen planes z = z_bottom, z = z_top (the
/// specimen axis is along z). Signed tetrahedra from a point on the axis over the lateral facets and
/// the two caps, each cap a fan from the ring's centroid (x, y) placed on its platen plane. Exact for
/// the polyhedron; the same construction as Tang et al. (2025), Eqs. 13-16, with the caps' true
/// polygons instead of cones on the initial diameter. Deterministic (fixed-order reduction).
Real enclosed_volume(const Membrane& m, Real z_bottom, Real z_top);

/// Total node mass (kg), for checks.
Real membrane_mass(const Membrane& m);

// ---- device helpers (also used by the tests on the host) ----

/// Edge metric (e1.e1, e1.e2, e2.e2) of the triangle (a, b, c), e1 = b - a, e2 = c - a.
KOKKOS_INLINE_FUNCTION Vec3 edge_metric(const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 e1 = b - a, e2 = c - a;
  return Vec3(dot(e1, e1), dot(e1, e2), dot(e2, e2));
}

/// CST node forces of one facet (N): St. Venant-Kirchhoff, plane stress, written in the facet's edge
/// basis so that no local frame (and no rotation) is needed. With the covariant Green strain
/// E_ij = (g_ij - G_ij) / 2 and the reference dual metric G^ij, the second Piola-Kirchhoff stress is
///   S^ij = lambda' G^ij (G^kl E_kl) + 2 mu G^ik E_kl G^lj,  lambda' = E nu / (1 - nu^2), mu = E / (2 (1 + nu)),
/// the plane-stress law written in any (oblique) basis; W = A0 t S^ij E_ij / 2 and
///   f_b = -dW/de1 = -A0 t (S^11 e1 + S^12 e2),  f_c = -A0 t (S^12 e1 + S^22 e2),  f_a = -f_b - f_c.
/// S symmetric makes the facet's moment vanish, so the triangle carries no spurious torque.
KOKKOS_INLINE_FUNCTION void cst_forces(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& G, const Vec3& Gi,
                                       Real area0, Real young, Real poisson, Real thickness, Vec3 f[3]) {
  const Vec3 e1 = b - a, e2 = c - a;
  const Vec3 g = Vec3(dot(e1, e1), dot(e1, e2), dot(e2, e2));
  const Real E11 = Real(0.5) * (g.x - G.x), E12 = Real(0.5) * (g.y - G.y), E22 = Real(0.5) * (g.z - G.z);
  const Real i11 = Gi.x, i12 = Gi.y, i22 = Gi.z;
  const Real tr = i11 * E11 + Real(2) * i12 * E12 + i22 * E22;
  // M = G^-1 E G^-1
  const Real A11 = i11 * E11 + i12 * E12, A12 = i11 * E12 + i12 * E22;
  const Real A21 = i12 * E11 + i22 * E12, A22 = i12 * E12 + i22 * E22;
  const Real M11 = A11 * i11 + A12 * i12, M12 = A11 * i12 + A12 * i22, M22 = A21 * i12 + A22 * i22;
  const Real lam = young * poisson / (Real(1) - poisson * poisson);
  const Real two_mu = young / (Real(1) + poisson);
  const Real S11 = lam * i11 * tr + two_mu * M11;
  const Real S12 = lam * i12 * tr + two_mu * M12;
  const Real S22 = lam * i22 * tr + two_mu * M22;
  const Real s = -area0 * thickness;
  f[1] = s * (S11 * e1 + S12 * e2);
  f[2] = s * (S12 * e1 + S22 * e2);
  f[0] = -(f[1] + f[2]);
}

/// Area vector S_f = (b - a) x (c - a) / 2 (m^2), outward for counter-clockwise vertices seen from outside.
KOKKOS_INLINE_FUNCTION Vec3 area_vector(const Vec3& a, const Vec3& b, const Vec3& c) {
  return Real(0.5) * cross(b - a, c - a);
}

/// Signed volume of the tetrahedron (o, a, b, c) (m^3): positive when (a, b, c) is counter-clockwise seen
/// from the side away from o.
KOKKOS_INLINE_FUNCTION Real signed_tet_volume(const Vec3& o, const Vec3& a, const Vec3& b, const Vec3& c) {
  return dot(a - o, cross(b - o, c - o)) / Real(6);
}

}  // namespace dem
