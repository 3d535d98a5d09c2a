#pragma once
/// Particle state in structure-of-arrays Views. Everything that moves with a particle when the
/// particles are re-sorted by cell lives here, so a permutation touches one place.
#include "kernels/core/types.hpp"

namespace dem {

/// Spheres. SI units: x (m), v (m/s), w (rad/s), f (N), m (N m), radius (m), mass (kg), inertia (kg m^2).
struct Particles {
  Vec3View x, v, w;     ///< position at t, velocity and spin at t - dt/2 (centred differences)
  Vec3View f, m;        ///< contact force and moment gathered this step
  Vec3View x_ref;       ///< position at the last contact rebuild (skin criterion)
  ScalarView radius, mass, inertia;
  GidView gid;          ///< global id: stable label of a particle, keys contact history
  IndexView specimen;   ///< which specimen of a batch the particle belongs to
  IndexView material;   ///< row of the material-pair table
  int n = 0;

  Particles() = default;
  explicit Particles(int count);
  /// Reorders every per-particle View so that new row k holds old row perm(k): into `spare`'s Views (allocated only
  /// where they are not of n rows), which then swap with these; `spare` keeps the old ones for the next time.
  void permute(const IndexView& perm, Particles& spare);
  /// The same with a spare of its own (an allocation of every View).
  void permute(const IndexView& perm) {
    Particles spare;
    permute(perm, spare);
  }
  /// Largest global id + 1 (sizes the gid -> local index map).
  std::uint32_t gid_bound() const;
};

}  // namespace dem
