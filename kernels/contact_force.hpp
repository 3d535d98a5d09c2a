#pragma once
/// Contact force kernels: geometry and kinematics of each candidate contact, then the contact law.
/// Candidates that do not touch get zero force and lose their history (the contact opened).
#include "accumulate.hpp"
#include "contact_law.hpp"
#include "domain.hpp"

namespace dem {

/// Largest overlap / radius of the step and where it happened (for blow-up detection).
struct OverlapStat {
  Real ratio = 0;
  int contact = -1;
};

/// Ball-ball forces with law RRLinear. Returns the largest overlap ratio.
OverlapStat compute_ball_forces(const Particles& p, ContactList& c, const ParamTableView& params, const Domain& dom,
                                Real dt);

/// Ball-wall forces (analytic walls and facets). A ball touching several facets at a shared edge or
/// vertex gets one contact: an edge/vertex hit yields to a face hit, or an equal hit of a lower facet
/// number, on any touching facet that holds the same edge or vertex.
OverlapStat compute_wall_forces(const Particles& p, ContactList& c, const Adjacency& adj, const WallSet& walls,
                                const FacetMesh& mesh, const ParamTableView& params, Real dt);

/// Applies the law to kinematics k of contact slot `s` and writes the results (shared by both kernels).
KOKKOS_INLINE_FUNCTION void apply_law(const ContactList& c, int s, const ContactParams& prm,
                                      const ContactKinematics& k, const Vec3& r1, const Vec3& r2) {
  ContactHistory h{load(c.fs, s), load(c.mr, s), c.flags(s)};
  const ContactOutput out = RRLinear::eval(prm, k, h);
  store(c.fs, s, h.fs);
  store(c.mr, s, h.mr);
  c.flags(s) = h.flags;
  store(c.fc, s, out.force);
  store(c.m1, s, cross(r1, out.force) + out.moment);
  if (c.m2.extent(0) > 0) store(c.m2, s, cross(r2, -out.force) - out.moment);
  c.fn(s) = out.fn;
}

/// Zeroes the results and history of a candidate that does not touch.
KOKKOS_INLINE_FUNCTION void open_contact(const ContactList& c, int s) {
  store(c.fs, s, Vec3());
  store(c.mr, s, Vec3());
  c.flags(s) = 0;
  store(c.fc, s, Vec3());
  store(c.m1, s, Vec3());
  if (c.m2.extent(0) > 0) store(c.m2, s, Vec3());
  c.fn(s) = 0;
}

}  // namespace dem
