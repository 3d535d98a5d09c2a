#pragma once
/// Rigid analytic walls (planes, discs, the inner face of a cylinder) and triangle facets (membrane).
/// Every wall answers one question for a ball centre x: the closest point of its surface on the
/// ball's side, from which the contact normal and overlap follow exactly as for two balls.
#include "kernels/core/vec3.hpp"

namespace dem {

enum WallKind : int {
  kPlane = 0,     ///< infinite, one-sided: normal points to the balls' side
  kDisc = 1,      ///< finite plate (platen): one-sided face plus its rim
  kCylinder = 2,  ///< inner face of a cylinder (mould): axis along normal, balls inside
};

/// Analytic walls, SoA. point: a point on the plane / disc centre / a point on the axis (m);
/// normal: unit normal / axis; velocity: rigid translation (m/s); radius: disc or cylinder radius (m).
struct WallSet {
  IndexView kind;
  Vec3View point, normal, velocity;
  ScalarView radius;
  IndexView material;
  int n = 0;
  WallSet() = default;
  explicit WallSet(int count)
      : kind("dem::walls::kind", count), point("dem::walls::point", count), normal("dem::walls::normal", count),
        velocity("dem::walls::velocity", count), radius("dem::walls::radius", count),
        material("dem::walls::material", count), n(count) {}
};

/// Triangle surface: node positions and velocities, triangles as node triples.
struct FacetMesh {
  Vec3View node_x, node_v;
  Index3View tri;
  int material = 0;
  int nnode = 0, ntri = 0;
  FacetMesh() = default;
  FacetMesh(int nodes, int tris)
      : node_x("dem::mesh::node_x", nodes), node_v("dem::mesh::node_v", nodes), tri("dem::mesh::tri", tris),
        nnode(nodes), ntri(tris) {}
};

/// Closest point of analytic wall w to x. Returns false where the wall cannot touch (the back of a
/// one-sided wall is treated as penetration, so only a disc's outside returns false beyond its rim).
KOKKOS_INLINE_FUNCTION bool wall_closest_point(int kind, const Vec3& p, const Vec3& nrm, Real radius,
                                               const Vec3& x, Vec3& cp) {
  const Vec3 d = x - p;
  const Real h = dot(d, nrm);
  if (kind == kPlane) {
    cp = x - h * nrm;
    return true;
  }
  const Vec3 radial = d - h * nrm;
  const Real rr = norm(radial);
  if (kind == kDisc) {
    if (h < 0) return false;  // behind the plate: balls never get there through the face
    cp = rr <= radius ? x - h * nrm : p + (radius / rr) * radial;
    return true;
  }
  // kCylinder: balls inside; the wall is the circle of the ball's own height.
  if (rr == Real(0)) return false;
  cp = p + h * nrm + (radius / rr) * radial;
  return true;
}

/// Signed distance from x to analytic wall along its contact normal n (from the ball towards the wall).
/// For one-sided walls a centre beyond the surface gives a negative distance (deep penetration).
KOKKOS_INLINE_FUNCTION bool wall_contact(int kind, const Vec3& p, const Vec3& nrm, Real radius, const Vec3& x,
                                         Vec3& n, Real& dist, Vec3& cp) {
  if (!wall_closest_point(kind, p, nrm, radius, x, cp)) return false;
  if (kind == kPlane || (kind == kDisc && norm2(tangential(x - p, nrm)) <= radius * radius)) {
    n = -nrm;
    dist = dot(x - p, nrm);
    return true;
  }
  if (kind == kCylinder) {
    const Vec3 radial = tangential(x - p, nrm);
    const Real rr = norm(radial);
    n = (Real(1) / rr) * radial;
    dist = radius - rr;
    return true;
  }
  const Vec3 d = cp - x;  // disc rim
  dist = norm(d);
  if (dist == Real(0)) return false;
  n = (Real(1) / dist) * d;
  return true;
}

/// Which feature of a triangle holds the closest point: the face, an edge (0: v0v1, 1: v1v2, 2: v2v0)
/// or a vertex (0, 1, 2).
enum FacetFeature : int { kFace = 0, kEdge = 1, kVertex = 2 };

struct FacetHit {
  Vec3 cp;        ///< closest point
  Real b[3];      ///< barycentric weights of cp
  int feature;    ///< FacetFeature
  int index;      ///< edge or vertex number within the triangle
};

/// Closest point on triangle (a, b, c) to x (Ericson, Real-Time Collision Detection, 5.1.5), with
/// the feature it lies on, so that a ball touching several facets at a shared edge or vertex can be
/// given exactly one contact.
KOKKOS_INLINE_FUNCTION FacetHit closest_on_triangle(const Vec3& x, const Vec3& a, const Vec3& b, const Vec3& c) {
  FacetHit h;
  const Vec3 ab = b - a, ac = c - a, ap = x - a;
  const Real d1 = dot(ab, ap), d2 = dot(ac, ap);
  auto set = [&](Real wa, Real wb, Real wc, int feat, int idx) {
    h.b[0] = wa; h.b[1] = wb; h.b[2] = wc; h.feature = feat; h.index = idx;
    h.cp = wa * a + wb * b + wc * c;
  };
  if (d1 <= 0 && d2 <= 0) { set(1, 0, 0, kVertex, 0); return h; }
  const Vec3 bp = x - b;
  const Real d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) { set(0, 1, 0, kVertex, 1); return h; }
  const Real vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) { const Real v = d1 / (d1 - d3); set(1 - v, v, 0, kEdge, 0); return h; }
  const Vec3 cpv = x - c;
  const Real d5 = dot(ab, cpv), d6 = dot(ac, cpv);
  if (d6 >= 0 && d5 <= d6) { set(0, 0, 1, kVertex, 2); return h; }
  const Real vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) { const Real w = d2 / (d2 - d6); set(1 - w, 0, w, kEdge, 2); return h; }
  const Real va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const Real w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    set(0, 1 - w, w, kEdge, 1);
    return h;
  }
  const Real denom = Real(1) / (va + vb + vc);
  const Real v = vb * denom, w = vc * denom, u = 1 - v - w;
  // A point on a shared edge must get the same feature from both facets whatever the rounding (FMA or
  // not), or both would claim a face contact: snap weights within 1e-10 of zero to the edge or vertex.
  constexpr Real tol = Real(1e-10);
  const bool su = u <= tol, sv = v <= tol, sw = w <= tol;
  if (su + sv + sw >= 2) {
    const int vtx = !su ? 0 : (!sv ? 1 : 2);
    set(vtx == 0, vtx == 1, vtx == 2, kVertex, vtx);
  } else if (sw) {
    set(u, v, w, kEdge, 0);
  } else if (su) {
    set(u, v, w, kEdge, 1);
  } else if (sv) {
    set(u, v, w, kEdge, 2);
  } else {
    set(u, v, w, kFace, 0);
  }
  return h;
}

/// Node ids of the feature a hit lies on (-1 where unused).
KOKKOS_INLINE_FUNCTION void feature_nodes(const FacetHit& h, const int t[3], int out[2]) {
  out[0] = -1; out[1] = -1;
  if (h.feature == kVertex) out[0] = t[h.index];
  if (h.feature == kEdge) { out[0] = t[h.index]; out[1] = t[(h.index + 1) % 3]; }
}

}  // namespace dem
