#pragma once
/// Contact laws composed from a normal, a tangential and a rolling part (the LIGGGHTS idea): each part
/// is a small device struct, and ContactLaw<N, T, R> calls them in a fixed order (normal first, since
/// the others are capped by the normal force). New physics (Hertz-Mindlin, rough-surface compliance,
/// wearing friction, twisting resistance) is a new part, not a change of the force kernels.
///
/// The default law is PFC's rolling resistance linear model `rrlinear` with the deformability method
/// (../shared/notes/physics_reference.md sections 1.1-1.2):
///   kn = pi r^2 E* / L,  r = min(R1, R2), L = R1 + R2 (ball-ball) or L = R1 (ball-facet)
///   ks = kn / kappa*,    Fs rotated with the contact plane, |Fs| <= mu_s Fn
///   kr = ks Rbar^2,      1/Rbar = 1/R1 + 1/R2 (Rbar = R1 at walls), M <- M - kr dtheta_bend, |M| <= mu_r Rbar Fn
/// No tension, no twist resistance, no rolling dashpot.
#include "vec3.hpp"

namespace dem {

/// Parameters of one material pair. Units: Pa, -, -, -, -.
struct ContactParams {
  Real emod = 1e8;     ///< effective modulus E* of the deformability method (Pa)
  Real kratio = 1.5;   ///< kappa* = kn / ks
  Real mu_s = 0.5;     ///< sliding friction coefficient
  Real mu_r = 0.0;     ///< rolling friction coefficient
  Real beta_n = 0.0;   ///< normal viscous damping ratio (PFC dp_nratio); 0 = off, force never tensile
};

/// Geometry and kinematics of one contact, seen from particle 1 ("i"); body 2 is a particle or a wall.
/// n points from 1 to 2; vrel is the velocity of 2 relative to 1 at the contact point; dtheta the
/// relative rotation increment (w2 - w1) dt. R2 = 0 marks a wall.
struct ContactKinematics {
  Vec3 n;
  Real overlap;   ///< m, > 0 when touching
  Real kn;        ///< N/m, normal stiffness of this pair (Normal::stiffness, computed once per contact)
  Real r1, r2;    ///< m
  Real m1, m2;    ///< kg, masses (m2 = 0 at walls), for the dashpot's reduced mass
  Vec3 vrel;      ///< m/s
  Vec3 dtheta;    ///< rad
  Real dt;        ///< s
};

/// History carried by a contact between steps (contact-plane vectors stored in global coordinates).
struct ContactHistory {
  Vec3 fs;               ///< shear force on particle 1 (N)
  Vec3 mr;               ///< rolling moment on particle 1 (N m)
  std::uint8_t flags = 0;
};

/// What a law returns for particle 1: total force and the extra (non-lever) moment.
struct ContactOutput {
  Vec3 force;    ///< N, on particle 1
  Vec3 moment;   ///< N m, on particle 1, excluding the lever arm of force
  Real fn = 0;   ///< N, linear normal force (dashpot excluded), >= 0
};

/// Scales a down to magnitude `cap` if it is longer; true if it was. Compares squares, so the common
/// elastic case costs no square root.
KOKKOS_INLINE_FUNCTION bool cap_to(Vec3& a, Real cap) {
  const Real m2 = norm2(a);
  if (m2 <= cap * cap) return false;
  a = cap > 0 ? (cap / kc::sqrt(m2)) * a : Vec3();
  return true;
}

/// Linear normal spring, stiffness from the deformability method.
struct NormalLinear {
  KOKKOS_INLINE_FUNCTION static Real stiffness(const ContactParams& p, Real r1, Real r2) {
    const Real r = r2 > 0 ? kc::min(r1, r2) : r1;
    const Real L = r2 > 0 ? r1 + r2 : r1;
    return Real(M_PI) * r * r * p.emod / L;
  }
  /// Linear normal force (>= 0) and the dashpot's addition (may make the sum tensile; clamped by caller).
  KOKKOS_INLINE_FUNCTION static Real force(const ContactParams&, const ContactKinematics& k) {
    return k.kn * k.overlap;
  }
  KOKKOS_INLINE_FUNCTION static Real dashpot(const ContactParams& p, const ContactKinematics& k) {
    if (p.beta_n == Real(0)) return 0;
    const Real mc = k.m2 > 0 ? k.m1 * k.m2 / (k.m1 + k.m2) : k.m1;
    return Real(2) * p.beta_n * kc::sqrt(mc * k.kn) * dot(k.vrel, k.n);  // < 0 when approaching
  }
};

/// Incremental linear shear spring with a Coulomb cap on the linear normal force.
struct TangentialCoulomb {
  KOKKOS_INLINE_FUNCTION static Vec3 update(const ContactParams& p, const ContactKinematics& k, Real fn,
                                             ContactHistory& h) {
    const Real ks = k.kn / p.kratio;
    Vec3 fs = rotate_into_plane(h.fs, k.n) + ks * k.dt * tangential(k.vrel, k.n);
    h.flags &= ~kSliding;
    if (cap_to(fs, p.mu_s * fn)) h.flags |= kSliding;
    h.fs = fs;
    return fs;
  }
};

/// Rolling resistance linear (Iwashita and Oda): bend rotation only, kr = ks Rbar^2, cap mu_r Rbar Fn.
struct RollingLinear {
  KOKKOS_INLINE_FUNCTION static Real rbar(Real r1, Real r2) { return r2 > 0 ? r1 * r2 / (r1 + r2) : r1; }
  KOKKOS_INLINE_FUNCTION static Vec3 update(const ContactParams& p, const ContactKinematics& k, Real fn,
                                             ContactHistory& h) {
    const Real rb = rbar(k.r1, k.r2);
    const Real kr = k.kn / p.kratio * rb * rb;
    Vec3 mr = rotate_into_plane(h.mr, k.n) + kr * tangential(k.dtheta, k.n);
    h.flags &= ~kRolling;
    if (cap_to(mr, p.mu_r * rb * fn)) h.flags |= kRolling;
    h.mr = mr;
    return mr;
  }
};

template <class Normal, class Tangential, class Rolling>
struct ContactLaw {
  /// Normal stiffness of a pair, to be stored in ContactKinematics::kn before eval.
  KOKKOS_INLINE_FUNCTION static Real stiffness(const ContactParams& p, Real r1, Real r2) {
    return Normal::stiffness(p, r1, r2);
  }
  /// Evaluates a touching contact (k.overlap > 0, k.kn set) and updates its history.
  KOKKOS_FORCEINLINE_FUNCTION static ContactOutput eval(const ContactParams& p, const ContactKinematics& k,
                                                   ContactHistory& h) {
    ContactOutput out;
    const Real fn = Normal::force(p, k);
    const Real fn_total = kc::max(fn - Normal::dashpot(p, k), Real(0));  // no tension
    const Vec3 fs = Tangential::update(p, k, fn, h);
    out.force = fs - fn_total * k.n;
    out.moment = Rolling::update(p, k, fn, h);
    out.fn = fn;
    h.flags |= kTouching;
    return out;
  }
};

using RRLinear = ContactLaw<NormalLinear, TangentialCoulomb, RollingLinear>;

}  // namespace dem
