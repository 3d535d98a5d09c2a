#pragma once
/// Contact laws composed from a normal, a tangential and a rolling part (the LIGGGHTS idea): each part
/// is a small device struct, and ContactLaw<N, T, R> calls them in a fixed order (normal first, since
/// the others are capped by the normal force and scaled by its tangent stiffness).
///
/// The default law is PFC's rolling resistance linear model `rrlinear` with the deformability method
/// (../shared/notes/physics_reference.md sections 1.1-1.2):
///   kn = pi r^2 E* / L,  r = min(R1, R2), L = R1 + R2 (ball-ball) or L = R1 (ball-facet)
///   ks = kn / kappa*,    Fs rotated with the contact plane, |Fs| <= mu_s Fn
///   kr = ks Rbar^2,      1/Rbar = 1/R1 + 1/R2 (Rbar = R1 at walls), M <- M - kr dtheta_bend, |M| <= mu_r Rbar Fn
/// No tension, no twist resistance, no rolling dashpot.
///
/// Model extensions (physics_reference.md section 4), each off by default and set per material pair; with
/// all of them off the arithmetic is the rrlinear model's, bit for bit:
///   Hertz-Mindlin stiffness (hertz_overlap = delta_ref / r > 0): Fn = kn delta^(3/2) / delta_ref^(1/2), the
///     secant stiffness equals kn at delta = delta_ref; the tangent stiffness kt = dFn/ddelta = 1.5 kn
///     (delta / delta_ref)^(1/2) grows with load as Mindlin's 2 E* a does, and the shear and rolling springs
///     follow it (ks = kt / kappa*; the shear history stores force, so a changing ks makes no spurious force).
///     The equivalent Hertz modulus is E_H = 3 kn / (4 sqrt(R* delta_ref)).
///   Rough-surface compliance (roughness = sigma / r > 0, sigma the combined rms roughness of the two
///     surfaces): an asperity layer that yields before the bulk. The bulk sees the overlap
///     delta_e = delta^2 / (delta + 2 sigma): about delta^2 / (2 sigma), soft, while delta << sigma (load carried
///     by few asperities); delta - 2 sigma once delta >> sigma (the asperities flattened), where the smooth
///     stiffness is recovered. d delta_e / d delta = delta (delta + 4 sigma) / (delta + 2 sigma)^2 scales the
///     normal, shear and rolling stiffness alike (Otsubo et al. 2017: roughness softens both), so the
///     softening is strongest at low confinement, the Greenwood-Tripp signature. The piecewise law of Otsubo
///     et al. is not reproduced (see the notes); this smooth form keeps one parameter and both limits.
///   Slip-weakening friction (wear in [0, 1), wear_slip = s_c / r): mu = mu_s (1 - wear (1 - exp(-s / s_c)))
///     with s the sliding distance accumulated by the contact (reset when it opens): asperities worn by
///     sliding, a lower residual strength after the peak. The default s_c is half a radius: much shorter,
///     the contacts wear before the peak and the effect is a lower mu_s (diagnose cannot tell them apart).
#include "vec3.hpp"

namespace dem {

/// Parameters of one material pair. Units: Pa, -, -, -, -.
struct ContactParams {
  Real emod = 1e8;     ///< effective modulus E* of the deformability method (Pa)
  Real kratio = 1.5;   ///< kappa* = kn / ks
  Real mu_s = 0.5;     ///< sliding friction coefficient
  Real mu_r = 0.0;     ///< rolling friction coefficient
  Real beta_n = 0.0;   ///< normal viscous damping ratio (PFC dp_nratio); 0 = off, force never tensile
  // Extensions (see the top of this file), 0 = off.
  Real hertz_overlap = 0.0;  ///< Hertz-Mindlin: overlap / r at which the secant stiffness equals kn
  Real roughness = 0.0;      ///< rough-surface compliance: combined rms roughness / r
  Real wear = 0.0;           ///< slip weakening: fraction of mu_s lost after long sliding
  Real wear_slip = 0.5;      ///< slip weakening: sliding distance / r over which friction decays by 1/e

  /// The same pair without the extensions (specimen preparation, which must not depend on them).
  ContactParams base() const {
    ContactParams b = *this;
    b.hertz_overlap = b.roughness = b.wear = 0;
    return b;
  }
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
  Real slip = 0;         ///< sliding distance accumulated while touching (m), for slip-weakening friction
};

/// What a law returns for particle 1: total force and the extra (non-lever) moment.
struct ContactOutput {
  Vec3 force;    ///< N, on particle 1
  Vec3 moment;   ///< N m, on particle 1, excluding the lever arm of force
  Real fn = 0;   ///< N, elastic normal force (dashpot excluded), >= 0
};

/// Scales a down to magnitude `cap` if it is longer; true if it was. Compares squares, so the common
/// elastic case costs no square root.
KOKKOS_INLINE_FUNCTION bool cap_to(Vec3& a, Real cap) {
  const Real m2 = norm2(a);
  if (m2 <= cap * cap) return false;
  a = cap > 0 ? (cap / kc::sqrt(m2)) * a : Vec3();
  return true;
}

/// Normal force and its tangent stiffness dFn/doverlap (N, N/m); the shear and rolling springs scale with it.
struct NormalResponse {
  Real fn;
  Real k;
};

/// The radius r of the deformability method: the smaller ball's, or the ball's at a wall.
KOKKOS_INLINE_FUNCTION Real contact_radius(Real r1, Real r2) { return r2 > 0 ? kc::min(r1, r2) : r1; }

/// Elastic normal spring: linear with the deformability method's kn, optionally Hertzian and rough.
struct NormalElastic {
  KOKKOS_INLINE_FUNCTION static Real stiffness(const ContactParams& p, Real r1, Real r2) {
    const Real r = contact_radius(r1, r2);
    const Real L = r2 > 0 ? r1 + r2 : r1;
    return Real(M_PI) * r * r * p.emod / L;
  }
  /// Largest tangent stiffness up to an overlap of overlap_max (m), for the critical time step.
  KOKKOS_INLINE_FUNCTION static Real max_stiffness(const ContactParams& p, Real r1, Real r2, Real overlap_max) {
    const Real kn = stiffness(p, r1, r2);
    if (p.hertz_overlap == Real(0)) return kn;  // roughness only softens
    const Real dref = p.hertz_overlap * contact_radius(r1, r2);
    return kc::max(kn, Real(1.5) * kn * kc::sqrt(overlap_max / dref));
  }
  /// Elastic normal force (>= 0) and tangent stiffness of a touching contact (k.overlap > 0, k.kn set).
  KOKKOS_INLINE_FUNCTION static NormalResponse response(const ContactParams& p, const ContactKinematics& k) {
    if (p.hertz_overlap == Real(0) && p.roughness == Real(0)) return {k.kn * k.overlap, k.kn};
    const Real r = contact_radius(k.r1, k.r2);
    Real d = k.overlap, dd = 1;  // bulk overlap and d(bulk overlap)/d(overlap)
    if (p.roughness > Real(0)) {
      const Real c = 2 * p.roughness * r, s = k.overlap + c;
      d = k.overlap * k.overlap / s;
      dd = k.overlap * (k.overlap + 2 * c) / (s * s);
    }
    if (p.hertz_overlap > Real(0)) {
      const Real root = kc::sqrt(d / (p.hertz_overlap * r));
      return {k.kn * d * root, Real(1.5) * k.kn * root * dd};
    }
    return {k.kn * d, k.kn * dd};
  }
  /// The dashpot's addition (may make the sum tensile; clamped by the caller), from the tangent stiffness.
  KOKKOS_INLINE_FUNCTION static Real dashpot(const ContactParams& p, const ContactKinematics& k, Real kt) {
    if (p.beta_n == Real(0)) return 0;
    const Real mc = k.m2 > 0 ? k.m1 * k.m2 / (k.m1 + k.m2) : k.m1;
    return Real(2) * p.beta_n * kc::sqrt(mc * kt) * dot(k.vrel, k.n);  // < 0 when approaching
  }
};

/// Incremental shear spring (ks = kt / kappa*) with a Coulomb cap on the elastic normal force; the friction
/// coefficient weakens with the contact's sliding distance when wear > 0.
struct TangentialCoulomb {
  KOKKOS_INLINE_FUNCTION static Real friction(const ContactParams& p, Real r, Real slip) {
    if (p.wear == Real(0)) return p.mu_s;
    return p.mu_s * (1 - p.wear * (1 - kc::exp(-slip / (p.wear_slip * r))));
  }
  KOKKOS_INLINE_FUNCTION static Vec3 update(const ContactParams& p, const ContactKinematics& k,
                                             const NormalResponse& nr, ContactHistory& h) {
    const Real ks = nr.k / p.kratio;
    Vec3 fs = rotate_into_plane(h.fs, k.n) + ks * k.dt * tangential(k.vrel, k.n);
    h.flags &= ~kSliding;
    if (p.wear == Real(0)) {
      if (cap_to(fs, p.mu_s * nr.fn)) h.flags |= kSliding;
    } else {
      // The slip of this step is the trial force beyond the cap over the spring stiffness.
      const Real trial = norm(fs);
      const Real cap = friction(p, contact_radius(k.r1, k.r2), h.slip) * nr.fn;
      if (cap_to(fs, cap)) {
        h.flags |= kSliding;
        if (ks > Real(0)) h.slip += (trial - cap) / ks;
      }
    }
    h.fs = fs;
    return fs;
  }
};

/// Rolling resistance linear (Iwashita and Oda): bend rotation only, kr = ks Rbar^2 (ks from the tangent
/// stiffness), cap mu_r Rbar Fn.
struct RollingLinear {
  KOKKOS_INLINE_FUNCTION static Real rbar(Real r1, Real r2) { return r2 > 0 ? r1 * r2 / (r1 + r2) : r1; }
  KOKKOS_INLINE_FUNCTION static Vec3 update(const ContactParams& p, const ContactKinematics& k,
                                             const NormalResponse& nr, ContactHistory& h) {
    const Real rb = rbar(k.r1, k.r2);
    const Real kr = nr.k / p.kratio * rb * rb;
    Vec3 mr = rotate_into_plane(h.mr, k.n) + kr * tangential(k.dtheta, k.n);
    h.flags &= ~kRolling;
    if (cap_to(mr, p.mu_r * rb * nr.fn)) h.flags |= kRolling;
    h.mr = mr;
    return mr;
  }
};

template <class Normal, class Tangential, class Rolling>
struct ContactLaw {
  /// Normal stiffness scale kn of a pair, to be stored in ContactKinematics::kn before eval.
  KOKKOS_INLINE_FUNCTION static Real stiffness(const ContactParams& p, Real r1, Real r2) {
    return Normal::stiffness(p, r1, r2);
  }
  /// Evaluates a touching contact (k.overlap > 0, k.kn set) and updates its history.
  KOKKOS_FORCEINLINE_FUNCTION static ContactOutput eval(const ContactParams& p, const ContactKinematics& k,
                                                   ContactHistory& h) {
    ContactOutput out;
    const NormalResponse nr = Normal::response(p, k);
    const Real fn_total = kc::max(nr.fn - Normal::dashpot(p, k, nr.k), Real(0));  // no tension
    const Vec3 fs = Tangential::update(p, k, nr, h);
    out.force = fs - fn_total * k.n;
    out.moment = Rolling::update(p, k, nr, h);
    out.fn = nr.fn;
    h.flags |= kTouching;
    return out;
  }
};

using RRLinear = ContactLaw<NormalElastic, TangentialCoulomb, RollingLinear>;

}  // namespace dem
