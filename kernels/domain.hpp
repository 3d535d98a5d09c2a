#pragma once
/// The simulation box: bounds and which axes are periodic. Non-periodic axes are open (walls confine).
#include "vec3.hpp"

namespace dem {

struct Domain {
  Real lo[3] = {0, 0, 0};   ///< m
  Real hi[3] = {0, 0, 0};   ///< m
  bool periodic[3] = {false, false, false};
  /// Homogeneous strain rate of the cell along each axis (1/s, extension positive). Particle velocities
  /// are fluctuations about this affine field, so a contact's relative velocity gains rate * branch.
  Real strain_rate[3] = {0, 0, 0};

  KOKKOS_INLINE_FUNCTION Real length(int d) const { return hi[d] - lo[d]; }

  /// Minimum-image separation for periodic axes (orthorhombic cell). Positions are wrapped at every
  /// rebuild and move less than the skin in between, so one shift always suffices (no floor call).
  KOKKOS_INLINE_FUNCTION Vec3 min_image(Vec3 d) const {
    Real c[3] = {d.x, d.y, d.z};
    for (int k = 0; k < 3; ++k) {
      if (!periodic[k]) continue;
      const Real L = length(k);
      if (c[k] > Real(0.5) * L) c[k] -= L;
      else if (c[k] < Real(-0.5) * L) c[k] += L;
    }
    return Vec3(c[0], c[1], c[2]);
  }

  /// Velocity of the affine field at separation d (m/s).
  KOKKOS_INLINE_FUNCTION Vec3 affine_velocity(const Vec3& d) const {
    return Vec3(strain_rate[0] * d.x, strain_rate[1] * d.y, strain_rate[2] * d.z);
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

}  // namespace dem
