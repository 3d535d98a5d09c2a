#pragma once
/// What each ball-ball contact adds to the sums of a cell's boundary control and records, one place for each
/// formula: a Simulation's reductions and a batch's (host/engine/cell_batch.cpp) call these.
///
/// The sums are taken per particle, then over the particles in gid order (OwnerSums): particle g's item is the sum,
/// in key order, of the terms of the touching contacts it owns. Neither which candidates the neighbour lists hold
/// (the skin's) nor the particles' order (each rebuild's) then changes a bit of them, so a run's bits do not depend on
/// when its lists were rebuilt.
#include "kernels/core/domain.hpp"
#include "kernels/core/specimen.hpp"
#include "kernels/core/walls.hpp"
#include "kernels/neighbor/contact_list.hpp"

namespace dem {

/// The Love-Weber term of a contact, f (x) l (N m, row-major, the force's component first): f the force one side
/// exerts on the other, l the branch from the first side to the second (ball to ball, or a ball's centre to its
/// contact point on a boundary); a boundary's own term x_c (x) f is the same product about the origin. The whole
/// tensor (N = 9) or its diagonal (N = 3), each component the same either way. The one formula of every contact
/// stress: the cell's and the specimen's sums on the device (specimen_stress) and a region's on the host
/// (host/engine/stress.hpp).
template <int N>
KOKKOS_INLINE_FUNCTION void love_weber_term(const Vec3& f, const Vec3& l, Real* v) {
  static_assert(N == 9 || N == 3, "the whole tensor or its diagonal");
  for (int q = 0; q < N; ++q) v[q] = f[N == 9 ? q / 3 : q] * l[N == 9 ? q % 3 : q];
}

/// Ball-ball contact k's Love-Weber term: the force particle 1 exerts on particle 2 (-fc, fc being the force on 1),
/// the branch from 1 to 2.
template <int N>
KOKKOS_INLINE_FUNCTION void love_weber_terms(const ContactList& c, int k, const ConstVec3View& x, const MinImage& image,
                                             Real* v) {
  love_weber_term<N>(Real(-1) * load(c.fc, k), image(load(x, c.j(k)) - load(x, c.i(k))), v);
}

/// Ball-wall contact k's terms (N = 18) of the ball at x: its Love-Weber term (0-8), branch from the ball's centre
/// to the contact point, and the boundary's x_c (x) f (9-17), each with the force the ball exerts on the wall
/// object (an analytic wall, or a facet after them). Nothing where the wall cannot touch.
KOKKOS_INLINE_FUNCTION void boundary_terms(const ContactList& c, int k, const Vec3& x, const WallSet& walls,
                                           const FacetMesh& mesh, Real* v) {
  const int obj = c.j(k);
  Vec3 cp;
  if (obj < walls.n) {
    if (!wall_closest_point(walls.kind(obj), load(walls.point, obj), load(walls.normal, obj), walls.radius(obj), x,
                            cp))
      return;
  } else {
    const int t = obj - walls.n;
    cp = closest_on_triangle(x, load(mesh.node_x, mesh.tri(t, 0)), load(mesh.node_x, mesh.tri(t, 1)),
                             load(mesh.node_x, mesh.tri(t, 2))).cp;
  }
  const Vec3 f = Real(-1) * load(c.fc, k);
  love_weber_term<9>(f, cp - x, v);
  love_weber_term<9>(f, cp, v + 9);
}

/// Contact k's share of the cell servo's stiffness (cell_stiffness): kn l_d^2 with kn = Fn / overlap, for a touching
/// contact; nothing otherwise.
KOKKOS_INLINE_FUNCTION void stiffness_terms(const ContactList& c, int k, const ConstVec3View& x,
                                            const ConstScalarView& r, const MinImage& image, Real* v) {
  const Real fn = c.fn(k);
  if (!(fn > 0)) return;
  const Vec3 l = image(load(x, c.j(k)) - load(x, c.i(k)));
  const Real overlap = r(c.i(k)) + r(c.j(k)) - norm(l);
  if (!(overlap > 0)) return;
  const Real kn = fn / overlap;
  v[0] = kn * l.x * l.x;
  v[1] = kn * l.y * l.y;
  v[2] = kn * l.z * l.z;
}

/// Contact k's share of the unbalanced-force ratio's mean contact force: |fc| and whether it touches.
KOKKOS_INLINE_FUNCTION void force_terms(const ContactList& c, int k, Real* v) {
  v[0] = norm(load(c.fc, k));
  v[1] = c.fn(k) > 0 ? Real(1) : Real(0);
}

/// The minimum image of a Simulation's one cell, for every particle.
struct OneImage {
  MinImage image;
  KOKKOS_INLINE_FUNCTION MinImage operator()(int) const { return image; }
};

/// The minimum image of a Simulation's one cell where it lies in device memory (a cell steered on the device).
struct CellImage {
  ConstCellView cell;
  KOKKOS_INLINE_FUNCTION MinImage operator()(int) const { return MinImage(cell()); }
};

/// The minimum image of particle i's specimen's cell, in a batch.
struct SpecimenImages {
  ConstIndexView owner;
  SpecimenParamsView spec;
  KOKKOS_INLINE_FUNCTION MinImage operator()(int i) const { return MinImage(spec(owner(i)).dom); }
};

/// love_weber_terms of a ball-ball contact; no ball-wall terms.
template <int N, class Images>
struct LoveWeberTerms {
  ConstVec3View x;
  Images images;
  KOKKOS_INLINE_FUNCTION void ball(const ContactList& c, int k, int i, Real* v) const {
    love_weber_terms<N>(c, k, x, images(i), v);
  }
  KOKKOS_INLINE_FUNCTION void wall(const ContactList&, int, int, Real*) const {}
};

/// A specimen's stress sums (N = 27, host/engine/stress.hpp: specimen_stress): the Love-Weber term of every contact
/// (0-8) and the boundary's term of its ball-wall contacts (9-17); the net-force term of each particle (18-26) is
/// SpecimenStressSums's, as OwnerSums adds contact terms only.
struct SpecimenStressTerms {
  ConstVec3View x;
  MinImage image;
  WallSet walls;
  FacetMesh mesh;
  KOKKOS_INLINE_FUNCTION void ball(const ContactList& c, int k, int, Real* v) const {
    love_weber_terms<9>(c, k, x, image, v);
  }
  KOKKOS_INLINE_FUNCTION void wall(const ContactList& c, int k, int i, Real* v) const {
    boundary_terms(c, k, load(x, i), walls, mesh, v);
  }
};

/// stiffness_terms of a ball-ball contact; no ball-wall terms.
template <class Images>
struct StiffnessTerms {
  ConstVec3View x;
  ConstScalarView r;
  Images images;
  KOKKOS_INLINE_FUNCTION void ball(const ContactList& c, int k, int i, Real* v) const {
    stiffness_terms(c, k, x, r, images(i), v);
  }
  KOKKOS_INLINE_FUNCTION void wall(const ContactList&, int, int, Real*) const {}
};

/// force_terms of every contact, ball-ball and ball-wall.
struct ForceTerms {
  KOKKOS_INLINE_FUNCTION void ball(const ContactList& c, int k, int, Real* v) const { force_terms(c, k, v); }
  KOKKOS_INLINE_FUNCTION void wall(const ContactList& c, int k, int, Real* v) const { force_terms(c, k, v); }
};

/// The contacts of a state by their particles, for OwnerSums: each particle's own ball-ball contacts (owner_ranges),
/// its ball-wall contacts (the Adjacency of the wall list by ball; none where empty), and the map from gid to the
/// particles' present order (gid_to_local).
struct ContactOwners {
  ContactList balls, walls;
  Index2View own;
  ConstIndexView wall_offset, wall_entry;
  ConstIndexView gid2local;
};

/// A tree item per gid (deterministic_reduce_lanes_to with W = 1, or a batch's segments of gids): the sum of
/// Terms' ball terms over the touching contacts the particle owns, in key order, and of its wall terms over its
/// touching ball-wall contacts, in their order. An open contact adds nothing: its terms are zero, and whether the
/// list holds it depends on the skin.
template <int N, class Terms>
struct OwnerSums {
  ContactOwners c;
  Terms terms;
  KOKKOS_INLINE_FUNCTION void operator()(const int g, int, Real (*vals)[N]) const {
    const int i = c.gid2local(g);
    if (i < 0) return;
    for (int s = c.own(i, 0); s < c.own(i, 1); ++s)
      if (c.balls.flags(s) != 0) add(vals[0], [&](Real* t) { terms.ball(c.balls, s, i, t); });
    if (c.wall_offset.extent(0) == 0) return;
    for (int a = c.wall_offset(i); a < c.wall_offset(i + 1); ++a) {
      const int s = c.wall_entry(a);
      if (c.walls.flags(s) != 0) add(vals[0], [&](Real* t) { terms.wall(c.walls, s, i, t); });
    }
  }

 private:
  template <class F>
  KOKKOS_INLINE_FUNCTION static void add(Real* sum, const F& f) {
    Real t[N] = {};
    f(t);
    for (int q = 0; q < N; ++q) sum[q] += t[q];
  }
};

/// specimen_stress's item per gid: SpecimenStressTerms over the particle's contacts (OwnerSums), then its net-force
/// term f (x) x (18-26), f the contact force the integrator gathered on it in the last step.
struct SpecimenStressSums {
  OwnerSums<27, SpecimenStressTerms> contacts;
  ConstVec3View f;
  KOKKOS_INLINE_FUNCTION void operator()(const int g, int lane, Real (*vals)[27]) const {
    contacts(g, lane, vals);
    const int i = contacts.c.gid2local(g);
    if (i < 0) return;
    Real t[9];
    love_weber_term<9>(load(f, i), load(contacts.terms.x, i), t);
    for (int q = 0; q < 9; ++q) vals[0][18 + q] += t[q];
  }
};

}  // namespace dem
