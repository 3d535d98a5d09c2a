#pragma once
/// The simulation box: bounds and which axes are periodic. Non-periodic axes are open (walls confine).
#include "kernels/core/vec3.hpp"

namespace dem {

struct Domain {
  Real lo[3] = {0, 0, 0};   ///< m
  Real hi[3] = {0, 0, 0};   ///< m
  bool periodic[3] = {false, false, false};
  /// Homogeneous strain rate of the cell along each axis (1/s, extension positive). Particle velocities
  /// are fluctuations about this affine field, so a contact's relative velocity gains rate * branch.
  Real strain_rate[3] = {0, 0, 0};

  KOKKOS_INLINE_FUNCTION Real length(int d) const { return hi[d] - lo[d]; }

  /// Minimum-image separation for periodic axes (orthorhombic cell); see MinImage.
  KOKKOS_INLINE_FUNCTION Vec3 min_image(const Vec3& d) const;

  /// Velocity of the affine field at separation d (m/s).
  template <class T>
  KOKKOS_INLINE_FUNCTION Vec3T<T> affine_velocity(const Vec3T<T>& d) const {
    return Vec3T<T>(strain_rate[0] * d.x, strain_rate[1] * d.y, strain_rate[2] * d.z);
  }
  KOKKOS_INLINE_FUNCTION Real volume() const { return length(0) * length(1) * length(2); }

  /// Maps a position into the primary cell along periodic axes.
  KOKKOS_INLINE_FUNCTION Vec3 wrap(Vec3 p) const {
    Real c[3] = {p.x, p.y, p.z};
    for (int k = 0; k < 3; ++k) {
      if (!periodic[k]) continue;
      const Real L = length(k);
      c[k] -= L * kc::floor((c[k] - lo[k]) / L);
      if (c[k] >= hi[k]) c[k] -= L;  // guards the rounding case (c - lo)/L == 1 - eps
    }
    return Vec3(c[0], c[1], c[2]);
  }

  /// wrap, for the coordinates outside [lo, hi] alone: the others (all of them after a step, step_wrap, and the cell's
  /// stretch, which keeps them within [lo, hi]) keep their bits.
  KOKKOS_INLINE_FUNCTION Vec3 contain(Vec3 p) const {
    const Vec3 w = wrap(p);
    Real c[3] = {p.x, p.y, p.z};
    for (int k = 0; k < 3; ++k)
      if (c[k] < lo[k] || c[k] > hi[k]) c[k] = w[k];
    return Vec3(c[0], c[1], c[2]);
  }
};

/// A step's wrap of positions into the periodic cell: a coordinate that left [lo, hi) in the step goes back by the
/// cell's length (a ball moves less than its radius a step, so once is enough); returns what was added to each.
/// Wrapped at every step, not at a rebuild, a ball's arithmetic does not depend on when its lists were rebuilt.
/// Lane by lane for a pack.
template <class T>
KOKKOS_INLINE_FUNCTION Vec3T<T> step_wrap(const Domain& dom, Vec3T<T>& x) {
  T c[3] = {x.x, x.y, x.z}, s[3] = {T(0), T(0), T(0)};
  for (int d = 0; d < 3; ++d) {
    if (!dom.periodic[d]) continue;
    const Real L = dom.length(d);
    s[d] = select(c[d] < T(dom.lo[d]), T(L), select(c[d] < T(dom.hi[d]), T(0), T(-L)));
    c[d] = select(s[d] != T(0), c[d] + s[d], c[d]);
  }
  x = Vec3T<T>(c[0], c[1], c[2]);
  return Vec3T<T>(s[0], s[1], s[2]);
}

/// The periodic cell's affine step over dt: each axis stretched about lo by 1 + rate dt. One formula for the cell's
/// bounds on the host and the particles on the device, which stay consistent bit for bit (no contraction anywhere,
/// CMakeLists.txt).
struct CellStretch {
  Real lo[3] = {0, 0, 0};
  Real f[3] = {1, 1, 1};

  CellStretch() = default;
  KOKKOS_INLINE_FUNCTION CellStretch(const Domain& dom, Real dt) {
    for (int d = 0; d < 3; ++d) {
      lo[d] = dom.lo[d];
      f[d] = 1 + dom.strain_rate[d] * dt;
    }
  }
  /// Coordinate x along axis d after the step.
  KOKKOS_INLINE_FUNCTION Real operator()(int d, Real x) const { return lo[d] + (x - lo[d]) * f[d]; }
  /// The cell's bounds after the step.
  KOKKOS_INLINE_FUNCTION void apply(Domain& dom) const {
    for (int d = 0; d < 3; ++d) dom.hi[d] = (*this)(d, dom.hi[d]);
  }
};

/// Whether the cell deforms (any strain rate).
inline bool stretching(const Domain& dom) {
  return dom.strain_rate[0] != 0 || dom.strain_rate[1] != 0 || dom.strain_rate[2] != 0;
}

/// How fast the cell's stretch moves two balls within `reach` (m) of each other apart or together (m/s): the cell's
/// share of the neighbour lists' travel (the largest rate times the reach).
KOKKOS_INLINE_FUNCTION Real stretch_speed(const Domain& dom, Real reach) {
  Real rate = 0;
  for (int d = 0; d < 3; ++d) rate = kc::fabs(dom.strain_rate[d]) > rate ? kc::fabs(dom.strain_rate[d]) : rate;
  return rate * reach;
}

/// The minimum-image shift of a domain, with the cell lengths worked out once: pair loops build one per
/// launch instead of re-reading the bounds for every pair (same arithmetic, same bits). Positions are
/// wrapped at every step (step_wrap), so one shift always suffices (no floor call).
struct MinImage {
  Real len[3] = {0, 0, 0};   ///< cell length of a periodic axis, 0 on an open one
  Real half[3] = {0, 0, 0};  ///< len / 2

  MinImage() = default;
  KOKKOS_INLINE_FUNCTION explicit MinImage(const Domain& dom) {
    for (int k = 0; k < 3; ++k) {
      len[k] = dom.periodic[k] ? dom.length(k) : Real(0);
      half[k] = Real(0.5) * len[k];
    }
  }
  /// Lane-wise on packs: the shift of each lane is the one its scalar would get.
  template <class T>
  KOKKOS_INLINE_FUNCTION Vec3T<T> operator()(const Vec3T<T>& d) const {
    return Vec3T<T>(shift(d.x, 0), shift(d.y, 1), shift(d.z, 2));
  }

 private:
  template <class T>
  KOKKOS_INLINE_FUNCTION T shift(const T& c, int k) const {
    if (len[k] == Real(0)) return c;
    return select(c > T(half[k]), c - len[k], select(c < T(-half[k]), c + len[k], c));
  }
};

KOKKOS_INLINE_FUNCTION Vec3 Domain::min_image(const Vec3& d) const { return MinImage(*this)(d); }

}  // namespace dem
