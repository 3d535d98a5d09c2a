#pragma once
/// What each ball-ball contact adds to the sums of a cell's boundary control and records, one place for each
/// formula: a Simulation's reductions and a batch's (host/engine/cell_batch.cpp) call these.
#include "kernels/core/domain.hpp"
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

}  // namespace dem
