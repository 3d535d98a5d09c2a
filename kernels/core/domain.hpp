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
};

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
  void apply(Domain& dom) const {
    for (int d = 0; d < 3; ++d) dom.hi[d] = (*this)(d, dom.hi[d]);
  }
};

/// Whether the cell deforms (any strain rate).
inline bool stretching(const Domain& dom) {
  return dom.strain_rate[0] != 0 || dom.strain_rate[1] != 0 || dom.strain_rate[2] != 0;
}

/// How fast the cell's stretch moves two balls within `reach` (m) of each other apart or together (m/s): the cell's
/// share of the neighbour lists' travel (the largest rate times the reach).
inline Real stretch_speed(const Domain& dom, Real reach) {
  Real rate = 0;
  for (int d = 0; d < 3; ++d) rate = kc::fabs(dom.strain_rate[d]) > rate ? kc::fabs(dom.strain_rate[d]) : rate;
  return rate * reach;
}

/// The minimum-image shift of a domain, with the cell lengths worked out once: pair loops build one per
/// launch instead of re-reading the bounds for every pair (same arithmetic, same bits). Positions are
/// wrapped at every rebuild and move less than the skin in between, so one shift always suffices (no floor
/// call).
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
