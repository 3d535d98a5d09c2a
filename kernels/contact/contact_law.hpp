#pragma once
/// Contact laws composed from a normal, a tangential and a rolling part (the LIGGGHTS idea): each part
/// is a small device struct, and ContactLaw<N, T, R, S> calls them in a fixed order (normal first, since
/// the others are capped by the normal force and scaled by its tangent stiffness). A part that keeps history
/// beyond the shear force and rolling moment keeps it in named slots (contact_params.hpp, HistorySlot) and says
/// which ones its parameters use (`slots`), so the kernels load and store only those.
///
/// The default law is PFC's rolling resistance linear model `rrlinear` with the deformability method
/// (Itasca's PFC manual, the `linear` and `rrlinear` contact models; docs/physics.md):
///   kn = pi r^2 E* / L,  r = min(R1, R2), L = R1 + R2 (ball-ball) or L = R1 (ball-facet)
///   ks = kn / kappa*,    Fs rotated with the contact plane, |Fs| <= mu_s Fn
///   kr = ks Rbar^2,      1/Rbar = 1/R1 + 1/R2 (Rbar = R1 at walls), M <- M - kr dtheta_bend, |M| <= mu_r Rbar Fn
/// No tension, no twist resistance, no rolling dashpot.
///
/// A law of its own, `hertz_mindlin` (PFC's hertz, YADE's Law2_ScGeom_MindlinPhys_Mindlin), swaps the normal part:
///   E* = G / (1 - nu) (two balls of one material: E / (2 (1 - nu^2))), R* = R1 R2 / (R1 + R2) (R1 at a wall),
///   Fn = 4/3 E* sqrt(R*) delta^(3/2), tangent kn = 2 E* a with a = sqrt(R* delta),
///   ks = 8 G* a = kn 2 (1 - nu) / (2 - nu) (Mindlin's no-slip stiffness, G* = G / (2 (2 - nu))),
/// and keeps the tangential, rolling and twisting parts (kr = ks Rbar^2 follows the load; YADE's krot is constant).
///
/// A third, `rrlinear_kr`, is rrlinear with the rolling spring's stiffness set by a coefficient of its own:
///   kr = kr_ratio ks Rbar^2 (kr_ratio = 1 is rrlinear), the cap mu_r Rbar Fn as before.
///
/// Model extensions (what a mu_s + mu_r linear law misses, each with its signature in triaxial data:
/// docs/calibration.md, Diagnosis), each off by default and set per material pair; with
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
///   Twisting resistance (twist > 0): a spring on the relative spin about n, k_tw = ks Rbar^2 (the rolling
///     spring's stiffness), capped at twist Rbar Fn: YADE's form with one coefficient, like mu_r for bending.
///     LAMMPS `twisting marshall` ties both to the contact radius a instead (k_tw = ks a^2 / 2, cap 2/3 a mu_s
///     Fn), which makes it negligible for stiff spheres; a free coefficient stands for rough or flattened
///     contacts. The moment is a scalar about n (slot kTwistSlot), so a turning contact plane carries it as is.
///   Adhesion (adhesion = a stress c > 0): touching balls pull on each other with the constant force
///     F_a = c (2 r)^2, the DMT idealisation of a pull-off force (a bond, or a capillary bridge at a wetted contact),
///     which acts while the balls overlap and ends when they part; the normal force is then kn delta - F_a, tensile
///     near separation. The Coulomb and rolling caps stay on the elastic force: an adhered contact under tension
///     holds no friction. Between balls only (a wall's r2 = 0): the membrane and the platens are not sticky. Per
///     contact it is a stress over the ball's cross-section, so at confinement sigma3 it acts as about c / sigma3 of
///     extra confinement: an apparent cohesion, largest relative to low sigma3, from the first strain on.
#include "kernels/contact/law_table.hpp"

namespace dem {

/// Scales a down to magnitude `cap` if it is longer (to zero if cap <= 0); returns where it was. Compares squares,
/// so an elastic contact's value never passes through a square root.
template <class T>
KOKKOS_INLINE_FUNCTION auto cap_to(Vec3T<T>& a, const T& cap) {
  const T m2 = norm2(a);
  const auto capped = m2 > cap * cap;
  if (any(capped)) a = select(capped, select(cap > T(0), (cap / kc::sqrt(m2)) * a, Vec3T<T>()), a);
  return capped;
}

/// The radius r of the deformability method: the smaller ball's, or the ball's at a wall.
template <class T>
KOKKOS_INLINE_FUNCTION T contact_radius(const T& r1, const Arg<T>& r2) {
  return select(r2 > T(0), kc::min(r1, r2), r1);
}

/// The effective radius R1 R2 / (R1 + R2), R1 at a wall: Rbar of the rolling spring and R* of Hertz's contact.
template <class T>
KOKKOS_INLINE_FUNCTION T effective_radius(const T& r1, const Arg<T>& r2) {
  return select(r2 > T(0), r1 * r2 / (r1 + r2), r1);
}

/// The rough-surface extension (roughness = sigma / r > 0, the top of the file): the bulk's overlap d and its derivative
/// dd over the contact's overlap, taken where `on`.
struct RoughLayer {
  template <class T>
  KOKKOS_INLINE_FUNCTION static auto on(const ContactParamsT<T>& p) {
    return p.roughness > T(0);
  }
  template <class M, class T>
  KOKKOS_FORCEINLINE_FUNCTION static void bulk(const ContactParamsT<T>& p, const M& on, const T& overlap, const T& r,
                                               T& d, T& dd) {
    const T c = 2 * p.roughness * r, s = overlap + c;
    d = select(on, overlap * overlap / s, d);
    dd = select(on, overlap * (overlap + 2 * c) / (s * s), dd);
  }
};

/// The Hertz extension of a linear normal spring (hertz_overlap = delta_ref / r > 0, the top of the file): the force
/// on the bulk's overlap d, kn the secant stiffness at delta_ref, where `on`; the linear spring's elsewhere.
struct HertzOverlap {
  template <class T>
  KOKKOS_INLINE_FUNCTION static auto on(const ContactParamsT<T>& p) {
    return p.hertz_overlap > T(0);
  }
  /// The largest tangent stiffness up to an overlap of overlap_max (m), from the linear spring's kn.
  KOKKOS_INLINE_FUNCTION static Real max_stiffness(const ContactParams& p, Real kn, Real r, Real overlap_max) {
    return kc::max(kn, Real(1.5) * kn * kc::sqrt(overlap_max / (p.hertz_overlap * r)));
  }
  template <class M, class T>
  KOKKOS_FORCEINLINE_FUNCTION static NormalResponseT<T> response(const ContactParamsT<T>& p, const M& on, const T& kn,
                                                                 const T& r, const T& d, const T& dd) {
    const T root = kc::sqrt(d / (p.hertz_overlap * r));
    const T kt = select(on, Real(1.5) * kn * root * dd, kn * dd);
    return {select(on, kn * d * root, kn * d), kt, kt / p.kratio};
  }
};

/// Elastic normal spring: linear with the deformability method's kn, optionally rough (RoughLayer) and Hertzian
/// (HertzOverlap).
struct NormalElastic {
  template <class T>
  KOKKOS_INLINE_FUNCTION static T stiffness(const ContactParamsT<T>& p, const Arg<T>& r1, const Arg<T>& r2) {
    const T r = contact_radius(r1, r2);
    const T L = select(r2 > T(0), r1 + r2, r1);
    return Real(M_PI) * r * r * p.emod / L;
  }
  /// A spring of the pair for a servo's gain (N/m): kn, linear up to the extensions.
  KOKKOS_INLINE_FUNCTION static Real servo_stiffness(const ContactParams& p, Real r1, Real r2) {
    return stiffness(p, r1, r2);
  }
  /// Largest tangent stiffness up to an overlap of overlap_max (m), for the critical time step.
  KOKKOS_INLINE_FUNCTION static MaxStiffness max_stiffness(const ContactParams& p, Real r1, Real r2,
                                                           Real overlap_max) {
    Real kn = stiffness(p, r1, r2);
    if (p.hertz_overlap != Real(0))  // roughness only softens
      kn = HertzOverlap::max_stiffness(p, kn, contact_radius(r1, r2), overlap_max);
    return {kn, kn / p.kratio};
  }
  /// Elastic normal force (>= 0) and tangent stiffness of a touching contact (k.overlap > 0, k.kn set).
  template <class T>
  KOKKOS_FORCEINLINE_FUNCTION static NormalResponseT<T> response(const ContactParamsT<T>& p,
                                                                 const ContactKinematicsT<T>& k) {
    const auto rough = RoughLayer::on(p), hertz = HertzOverlap::on(p);
    if (!any(rough | hertz)) return {k.kn * k.overlap, k.kn, k.kn / p.kratio};
    const T r = contact_radius(k.r1, k.r2);
    T d = k.overlap, dd = 1;  // bulk overlap and d(bulk overlap)/d(overlap)
    if (any(rough)) RoughLayer::bulk(p, rough, k.overlap, r, d, dd);
    if (any(hertz)) return HertzOverlap::response(p, hertz, k.kn, r, d, dd);
    return {k.kn * d, k.kn * dd, k.kn * dd / p.kratio};
  }
  /// The adhesive pull of a touching pair of balls (N, >= 0; 0 at walls), subtracted from the normal force.
  template <class T>
  KOKKOS_FORCEINLINE_FUNCTION static T adhesion(const ContactParamsT<T>& p, const ContactKinematicsT<T>& k) {
    const T r = contact_radius(k.r1, k.r2);
    return select(k.r2 > T(0), 4 * p.adhesion * r * r, T(0));
  }
  /// The dashpot's addition (may make the sum tensile; clamped by the caller), from the tangent stiffness.
  template <class T>
  KOKKOS_FORCEINLINE_FUNCTION static T dashpot(const ContactParamsT<T>& p, const ContactKinematicsT<T>& k,
                                                const T& kt) {
    const auto on = p.beta_n != T(0);
    if (!any(on)) return 0;
    const T mc = select(k.m2 > T(0), k.m1 * k.m2 / (k.m1 + k.m2), k.m1);
    return select(on, Real(2) * p.beta_n * kc::sqrt(mc * kt) * dot(k.vrel, k.n), T(0));  // < 0 when approaching
  }
};

/// Hertz's normal spring with Mindlin's shear stiffness (the top of the file); the dashpot and adhesion as
/// NormalElastic's. kn of the kinematics is 4/3 E* sqrt(R*) (N/m^1.5).
struct NormalHertzMindlin : NormalElastic {
  template <class T>
  KOKKOS_INLINE_FUNCTION static T stiffness(const ContactParamsT<T>& p, const Arg<T>& r1, const Arg<T>& r2) {
    return Real(4.0 / 3.0) * p.shear_modulus / (1 - p.poisson) * kc::sqrt(effective_radius(r1, r2));
  }
  template <class T>
  KOKKOS_INLINE_FUNCTION static T shear_ratio(const ContactParamsT<T>& p) {
    return 2 * (1 - p.poisson) / (2 - p.poisson);
  }
  /// For a servo's gain: the tangent stiffness at an overlap of 0.1% of r, about that of glass beads at 100 kPa.
  KOKKOS_INLINE_FUNCTION static Real servo_stiffness(const ContactParams& p, Real r1, Real r2) {
    return Real(1.5) * stiffness(p, r1, r2) * kc::sqrt(Real(1e-3) * contact_radius(r1, r2));
  }
  KOKKOS_INLINE_FUNCTION static MaxStiffness max_stiffness(const ContactParams& p, Real r1, Real r2,
                                                           Real overlap_max) {
    const Real kn = Real(1.5) * stiffness(p, r1, r2) * kc::sqrt(overlap_max);
    return {kn, kn * shear_ratio(p)};
  }
  template <class T>
  KOKKOS_FORCEINLINE_FUNCTION static NormalResponseT<T> response(const ContactParamsT<T>& p,
                                                                 const ContactKinematicsT<T>& k) {
    const T root = kc::sqrt(k.overlap);
    const T kt = Real(1.5) * k.kn * root;
    return {k.kn * k.overlap * root, kt, kt * shear_ratio(p)};
  }
};

/// Incremental shear spring (ks from the normal part) with a Coulomb cap on the elastic normal force; the friction
/// coefficient weakens with the contact's sliding distance when wear > 0.
struct TangentialCoulomb {
  template <class T>
  KOKKOS_INLINE_FUNCTION static unsigned slots(const ContactParamsT<T>& p) {
    return any(p.wear != T(0)) ? 1u << kSlipSlot : 0u;
  }
  template <class T>
  KOKKOS_FORCEINLINE_FUNCTION static T friction(const ContactParamsT<T>& p, const Arg<T>& r, const Arg<T>& slip) {
    const auto worn = p.wear != T(0);
    if (!any(worn)) return p.mu_s;
    return select(worn, p.mu_s * (1 - p.wear * (1 - kc::exp(-slip / (p.wear_slip * r)))), p.mu_s);
  }
  template <class T>
  KOKKOS_FORCEINLINE_FUNCTION static Vec3T<T> update(const ContactParamsT<T>& p, const ContactKinematicsT<T>& k,
                                                const NormalResponseT<T>& nr, ContactHistoryT<T>& h) {
    const T ks = nr.ks;
    Vec3T<T> fs = rotate_into_plane(h.fs, k.n) + ks * k.dt * tangential(k.vrel, k.n);
    const auto worn = p.wear != T(0);
    if (!any(worn)) {
      set_flag(h.flags, cap_to(fs, p.mu_s * nr.fn), kSliding);
    } else {
      // The slip of this step is the trial force beyond the cap over the spring stiffness.
      const T trial = norm(fs);
      T& slip = h.slot[kSlipSlot];
      const T cap = friction(p, contact_radius(k.r1, k.r2), slip) * nr.fn;
      const auto capped = cap_to(fs, cap);
      set_flag(h.flags, capped, kSliding);
      slip = select(worn & capped & (ks > T(0)), slip + (trial - cap) / ks, slip);
    }
    h.fs = fs;
    return fs;
  }
};

/// The rolling spring's stiffness from ks Rbar^2: PFC's rrlinear takes it as it is.
struct RollingStiffnessOfShear {
  template <class T>
  KOKKOS_FORCEINLINE_FUNCTION static T of(const ContactParamsT<T>&, const T& ks_rbar2) {
    return ks_rbar2;
  }
};
/// ... or scaled by a coefficient of its own, kr_ratio (as YADE's alphaKr and other codes' rolling stiffness
/// coefficients): a rolling spring stiffer or softer than the shear spring's, at the same cap.
struct RollingStiffnessScaled {
  template <class T>
  KOKKOS_FORCEINLINE_FUNCTION static T of(const ContactParamsT<T>& p, const T& ks_rbar2) {
    return p.kr_ratio * ks_rbar2;
  }
};

/// Rolling resistance linear (Iwashita and Oda): bend rotation only, kr = ks Rbar^2 (ks from the normal part) as
/// Stiffness makes it, cap mu_r Rbar Fn.
template <class Stiffness>
struct RollingSpring {
  template <class T>
  KOKKOS_FORCEINLINE_FUNCTION static Vec3T<T> update(const ContactParamsT<T>& p, const ContactKinematicsT<T>& k,
                                                const NormalResponseT<T>& nr, ContactHistoryT<T>& h) {
    const T rb = effective_radius(k.r1, k.r2);
    const T kr = Stiffness::of(p, nr.ks * rb * rb);
    Vec3T<T> mr = rotate_into_plane(h.mr, k.n) + kr * tangential(k.dtheta, k.n);
    set_flag(h.flags, cap_to(mr, p.mu_r * rb * nr.fn), kRolling);
    h.mr = mr;
    return mr;
  }
};

/// Twisting resistance, off where twist = 0 (see the top of the file): adds the spin moment on particle 1 about n to
/// `moment`. Lanes without it keep their moment's bits and their history (adding a zero would turn a -0 into +0).
struct TwistingLinear {
  template <class T>
  KOKKOS_INLINE_FUNCTION static unsigned slots(const ContactParamsT<T>& p) {
    return any(p.twist != T(0)) ? 1u << kTwistSlot : 0u;
  }
  template <class T>
  KOKKOS_FORCEINLINE_FUNCTION static void update(const ContactParamsT<T>& p, const ContactKinematicsT<T>& k,
                                            const NormalResponseT<T>& nr, ContactHistoryT<T>& h, Vec3T<T>& moment) {
    const auto on = p.twist != T(0);
    if (!any(on)) return;
    const T rb = effective_radius(k.r1, k.r2);
    const T cap = p.twist * rb * nr.fn;
    const T trial = h.slot[kTwistSlot] + nr.ks * rb * rb * dot(k.dtheta, k.n);
    const auto capped = trial * trial > cap * cap;
    const T mt = select(capped, select(trial > T(0), cap, -cap), trial);
    h.slot[kTwistSlot] = select(on, mt, h.slot[kTwistSlot]);
    moment = select(on, moment + mt * k.n, moment);
  }
};

template <class Normal, class Tangential, class Rolling, class Twisting>
struct ContactLaw {
  using NormalPart = Normal;
  /// The history slots that parameters p use (bits 1 << HistorySlot): the kernels load and store only these.
  template <class T>
  KOKKOS_INLINE_FUNCTION static unsigned slots(const ContactParamsT<T>& p) {
    return Tangential::slots(p) | Twisting::slots(p);
  }
  /// Normal stiffness scale kn of a pair, to be stored in ContactKinematics::kn before eval.
  template <class T>
  KOKKOS_INLINE_FUNCTION static T stiffness(const ContactParamsT<T>& p, const Arg<T>& r1, const Arg<T>& r2) {
    return Normal::stiffness(p, r1, r2);
  }
  /// Evaluates a touching contact (k.overlap > 0, k.kn set) and updates its history.
  template <class T>
  KOKKOS_FORCEINLINE_FUNCTION static ContactOutputT<T> eval(const ContactParamsT<T>& p, const ContactKinematicsT<T>& k,
                                                           ContactHistoryT<T>& h) {
    ContactOutputT<T> out;
    const NormalResponseT<T> nr = Normal::response(p, k);
    T fn_total = kc::max(nr.fn - Normal::dashpot(p, k, nr.k), T(0));  // no tension but adhesion's
    // Lanes without adhesion keep their bits (subtracting a zero would turn a -0 into +0).
    const auto sticky = p.adhesion != T(0);
    if (any(sticky)) fn_total = select(sticky, fn_total - Normal::adhesion(p, k), fn_total);
    const Vec3T<T> fs = Tangential::update(p, k, nr, h);
    out.force = fs - fn_total * k.n;
    out.moment = Rolling::update(p, k, nr, h);
    Twisting::update(p, k, nr, h, out.moment);
    out.fn = nr.fn;
    set_flag(h.flags, true, kTouching);
    return out;
  }
};

using RollingLinear = RollingSpring<RollingStiffnessOfShear>;
using RRLinear = ContactLaw<NormalElastic, TangentialCoulomb, RollingLinear, TwistingLinear>;
using HertzMindlin = ContactLaw<NormalHertzMindlin, TangentialCoulomb, RollingLinear, TwistingLinear>;
/// rrlinear with the rolling spring's own coefficient: kr = kr_ratio ks Rbar^2.
using RRLinearKr = ContactLaw<NormalElastic, TangentialCoulomb, RollingSpring<RollingStiffnessScaled>, TwistingLinear>;

/// The laws, in ContactLawId's order (law_table.hpp: LawTable).
static_assert(kContactLaws == 3, "each ContactLawId needs its law in ContactLaws, in the enum's order");
using ContactLaws = LawTable<RRLinear, HertzMindlin, RRLinearKr>;

}  // namespace dem
