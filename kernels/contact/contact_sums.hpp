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
#include "kernels/neighbor/contact_list.hpp"

namespace dem {

/// Contact k's Love-Weber terms -fc_a l_b (N m), l the branch from particle 1 to 2: the whole tensor row-major
/// (N = 9) or its diagonal (N = 3), each component the same either way.
template <int N>
KOKKOS_INLINE_FUNCTION void love_weber_terms(const ContactList& c, int k, const ConstVec3View& x, const MinImage& image,
                                             Real* v) {
  static_assert(N == 9 || N == 3, "the whole tensor or its diagonal");
  const Vec3 f = load(c.fc, k);
  const Vec3 l = image(load(x, c.j(k)) - load(x, c.i(k)));
  for (int q = 0; q < N; ++q) v[q] = -f[N == 9 ? q / 3 : q] * l[N == 9 ? q % 3 : q];
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

}  // namespace dem
