/// Unit tests of the rrlinear contact law parts (kernels/contact/contact_law.hpp), evaluated on the host as
/// plain structs: no Simulation, no time loop. Expected values come from the PFC formulas
/// (kn = pi r^2 E*/L, ks = kn/kratio, |Fs| <= mu_s Fn, kr = ks Rbar^2, |Mr| <= mu_r Rbar Fn), written
/// out independently here.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <utility>
#include <vector>

#include "host/engine/builder.hpp"
#include "test_util.hpp"
#include "kernels/contact/contact_force.hpp"
#include "kernels/contact/contact_law.hpp"
#include "kernels/core/det_math.hpp"
#include "kernels/core/vec3.hpp"

using namespace dem;

namespace {

using test::kPi;


Vec3 unit(const Vec3& a) { return (1.0 / norm(a)) * a; }

/// kn of the deformability method, written out here: pi r^2 E* / L, r = min radius (the ball's at a
/// wall), L = R1 + R2 (R1 at a wall).
double kn_formula(double emod, double r1, double r2) {
  const double r = r2 > 0 ? std::min(r1, r2) : r1;
  return kPi * r * r * emod / (r2 > 0 ? r1 + r2 : r1);
}

/// A touching contact with unit normal n (from 1 to 2), overlap d, radii r1, r2 (r2 = 0: wall). The
/// force kernels store the pair's stiffness in k.kn before calling the law; here it comes from the
/// formula above.
ContactKinematics kin(const ContactParams& p, const Vec3& n, double d, double r1, double r2, double dt) {
  ContactKinematics k;
  k.n = n;
  k.overlap = d;
  k.kn = kn_formula(p.emod, r1, r2);
  k.r1 = r1;
  k.r2 = r2;
  k.m1 = 1e-5;  // m2 = 0: reduced mass = m1
  k.m2 = 0;
  k.vrel = Vec3();
  k.dtheta = Vec3();
  k.dt = dt;
  return k;
}

}  // namespace

// ---------------------------------------------------------------------------------------------------
// Stiffness: deformability method. Pure arithmetic on a handful of doubles: 1e-14 relative is a few
// ulps of rounding in pi*r*r*E/L.
TEST(ContactLaw, NormalStiffnessDeformabilityMethod) {
  const ContactParams p = test::law(7.3e7, 1.5, 0.5, 0.1);
  const double R = 1.3e-3;
  // Equal balls: A = pi R^2, L = 2R -> kn = pi R E*/2.
  EXPECT_NEAR(NormalElastic::stiffness(p, R, R), kPi * R * p.emod / 2, 1e-14 * kPi * R * p.emod / 2);
  // Ball-wall (r2 = 0): A = pi R^2, L = R -> kn = pi R E*, twice the ball-ball value.
  EXPECT_NEAR(NormalElastic::stiffness(p, R, 0), kPi * R * p.emod, 1e-14 * kPi * R * p.emod);
  // Unequal: r = min(R1, R2), L = R1 + R2, and symmetric in the two radii.
  const double R1 = 0.8e-3, R2 = 1.2e-3;
  const double expect = kPi * R1 * R1 * p.emod / (R1 + R2);
  EXPECT_NEAR(NormalElastic::stiffness(p, R1, R2), expect, 1e-14 * expect);
  EXPECT_NEAR(NormalElastic::stiffness(p, R2, R1), expect, 1e-14 * expect);
  // A ball-wall contact uses the ball's own radius even when it is the larger one.
  EXPECT_NEAR(NormalElastic::stiffness(p, R2, 0), kPi * R2 * p.emod, 1e-14 * kPi * R2 * p.emod);
  // The law's stiffness (what the force kernels store in ContactKinematics::kn) is the same.
  EXPECT_NEAR(RRLinear::stiffness(p, R1, R2), expect, 1e-14 * expect);
  EXPECT_NEAR(RRLinear::stiffness(p, R, 0), kPi * R * p.emod, 1e-14 * kPi * R * p.emod);
  // The law's normal force is kn * overlap, reported in out.fn and pushing particle 1 away from 2.
  const Vec3 n = unit(Vec3(0.3, -0.4, 0.86));
  ContactHistory h;
  const double d = 2e-6;
  const ContactOutput out = RRLinear::eval(p, kin(p, n, d, R1, R2, 1e-7), h);
  EXPECT_NEAR(out.fn, expect * d, 1e-13 * expect * d);
  EXPECT_NEAR(dot(out.force, n), -expect * d, 1e-13 * expect * d);
  EXPECT_TRUE(h.flags & kTouching);
}

// ---------------------------------------------------------------------------------------------------
// Coulomb: constant overlap, constant tangential relative velocity. Each step adds exactly
// ks * |v_t| * dt to the shear force (incremental spring), which is tested to 1e-12 relative (a few
// hundred additions of equal increments: accumulated rounding is ~N ulps ~ 1e-13). The cap
// mu_s * Fn is applied by rescaling, so its magnitude is exact to rounding: 1e-12.
TEST(ContactLaw, CoulombShearGrowsThenSaturates) {
  const ContactParams p = test::law(1e8, 1.5, 0.4, 0.0);
  const double R1 = 1e-3, R2 = 0.9e-3, dt = 1e-7, d = 1e-6;
  const Vec3 n = unit(Vec3(1, 2, 2));
  const Vec3 t = unit(cross(n, Vec3(0, 0, 1)));  // a tangent direction
  const double vt = 0.05;
  ContactKinematics k = kin(p, n, d, R1, R2, dt);
  // Relative velocity of 2 w.r.t. 1 has a tangential part vt*t and a normal part that must not enter
  // the shear spring (beta_n = 0, so it does not change the normal force either).
  k.vrel = vt * t + 0.3 * n;
  const double kn = kPi * R2 * R2 * p.emod / (R1 + R2);
  const double ks = kn / p.kratio;
  const double fn = kn * d;
  const double cap = p.mu_s * fn;
  const double inc = ks * vt * dt;
  const int nsat = static_cast<int>(std::ceil(cap / inc));
  ASSERT_GT(nsat, 20) << "test set-up: the elastic phase should last many steps";
  ASSERT_LT(nsat, 2000);
  ContactHistory h;
  bool saturated = false;
  for (int s = 1; s <= nsat + 50; ++s) {
    const ContactOutput out = RRLinear::eval(p, k, h);
    const Vec3 fs = h.fs;  // shear force on particle 1 (history = this step's shear force)
    const double mag = norm(fs);
    // The total force is the shear force minus the normal force along n (rounding of kn*d: 1e-13 fn).
    EXPECT_NEAR(norm(out.force - (fs - fn * n)), 0.0, 1e-13 * fn);
    const double elastic = s * inc;
    if (elastic <= cap * (1 - 1e-9)) {
      EXPECT_NEAR(mag, elastic, 1e-12 * elastic) << "step " << s;
      EXPECT_FALSE(h.flags & kSliding) << "step " << s;
    } else if (elastic >= cap * (1 + 1e-9)) {
      saturated = true;
      EXPECT_NEAR(mag, cap, 1e-12 * cap) << "step " << s;
      EXPECT_TRUE(h.flags & kSliding) << "step " << s;
    }
    // The force on particle 1 points along the velocity of 2 relative to 1: it opposes the slip of 1
    // relative to 2, and it lies in the contact plane.
    EXPECT_NEAR(dot(fs, t), mag, 1e-12 * mag);
    EXPECT_LT(std::fabs(dot(fs, n)), 1e-12 * mag);
  }
  EXPECT_TRUE(saturated);
  // Reversal: slipping backwards unloads the spring elastically, by ks*v*dt per step, from the cap.
  k.vrel = -vt * t;
  for (int s = 1; s <= 10; ++s) {
    RRLinear::eval(p, k, h);
    EXPECT_NEAR(dot(h.fs, t), cap - s * inc, 1e-11 * cap) << "unloading step " << s;
    EXPECT_FALSE(h.flags & kSliding);
  }
}

// The shear cap uses the linear normal force, not the dashpot-augmented one (PFC: F_n^l).
TEST(ContactLaw, CoulombCapUsesLinearNormalForce) {
  const ContactParams p = test::law(1e8, 1.0, 0.5, 0.0, 0.5);
  const double R = 1e-3, d = 1e-6;
  const Vec3 n(0, 0, 1);
  ContactKinematics k = kin(p, n, d, R, R, 1e-6);
  k.vrel = Vec3(10.0, 0, -0.2);  // approaching (dashpot adds repulsion) and sliding hard
  ContactHistory h;
  const ContactOutput out = RRLinear::eval(p, k, h);
  const double kn = kPi * R * p.emod / 2;
  EXPECT_TRUE(h.flags & kSliding);
  EXPECT_NEAR(norm(h.fs), p.mu_s * kn * d, 1e-12 * p.mu_s * kn * d);
  // The dashpot did act on the normal force: 2 beta sqrt(mc kn) |vn| on top of kn d.
  const double fnt = kn * d + 2 * p.beta_n * std::sqrt(k.m1 * kn) * 0.2;
  EXPECT_NEAR(-dot(out.force, n), fnt, 1e-12 * fnt);
  EXPECT_NEAR(out.fn, kn * d, 1e-12 * kn * d);
}

// ---------------------------------------------------------------------------------------------------
// Rolling: relative bend rotation accumulates M = kr * theta with kr = ks Rbar^2 (rrlinear_kr: kr_ratio ks Rbar^2)
// until mu_r Rbar Fn, through the table of laws as the kernels call it. Same rounding argument as for the shear
// spring: 1e-12 relative.
namespace {
void check_rolling(double R1, double R2, double rbar_expect, ContactLawId law = kRRLinear, double kr_ratio = 1) {
  ContactParams p = test::law(1e8, 2.0, 0.5, 0.3);
  p.law = law;
  p.kr_ratio = kr_ratio;
  const double dt = 1e-7, d = 2e-6;
  const Vec3 n = unit(Vec3(-0.2, 0.5, 1.0));
  const Vec3 t = unit(cross(n, Vec3(1, 0, 0)));
  const double kn = R2 > 0 ? kPi * std::min(R1, R2) * std::min(R1, R2) * p.emod / (R1 + R2) : kPi * R1 * p.emod;
  const double kr = kr_ratio * kn / p.kratio * rbar_expect * rbar_expect;
  const double cap = p.mu_r * rbar_expect * kn * d;
  const double wrel = 20.0;  // rad/s, (w2 - w1) along t, plus a twist about n that must be ignored
  ContactKinematics k = kin(p, n, d, R1, R2, dt);
  k.dtheta = dt * (wrel * t + 35.0 * n);
  const double inc = kr * wrel * dt;
  const int nsat = static_cast<int>(std::ceil(cap / inc));
  ASSERT_GT(nsat, 20);
  ASSERT_LT(nsat, 5000);
  ContactHistory h;
  bool saturated = false;
  for (int s = 1; s <= nsat + 30; ++s) {
    const ContactOutput out = ContactLaws::eval(p, k, h);
    const double mag = norm(out.moment);
    const double elastic = s * inc;
    if (elastic <= cap * (1 - 1e-9)) {
      EXPECT_NEAR(mag, elastic, 1e-12 * elastic) << "step " << s;
      EXPECT_FALSE(h.flags & kRolling);
    } else if (elastic >= cap * (1 + 1e-9)) {
      saturated = true;
      EXPECT_NEAR(mag, cap, 1e-12 * cap) << "step " << s;
      EXPECT_TRUE(h.flags & kRolling);
    }
    // The moment on 1 follows the rotation of 2 relative to 1 (resists the relative rolling) and has
    // no twist component.
    EXPECT_NEAR(dot(out.moment, t), mag, 1e-12 * mag);
    EXPECT_LT(std::fabs(dot(out.moment, n)), 1e-12 * mag);
    // Rolling never makes the contact slide (no tangential velocity at the contact point here).
    EXPECT_FALSE(h.flags & kSliding);
  }
  EXPECT_TRUE(saturated);
}
}  // namespace

TEST(ContactLaw, RollingMomentCapBallBall) {
  const double R = 1e-3;
  check_rolling(R, R, R / 2);                       // 1/Rbar = 2/R
  check_rolling(0.8e-3, 1.2e-3, 0.8e-3 * 1.2e-3 / 2.0e-3);
}

TEST(ContactLaw, RollingMomentCapWall) { check_rolling(1e-3, 0, 1e-3); }  // Rbar = R1 at walls

// rrlinear_kr's rolling spring is kr_ratio times rrlinear's, stiffer and softer, at the same cap (the cap is reached
// after 1/kr_ratio of the steps); rrlinear ignores the field.
TEST(ContactLaw, TheRollingStiffnessLawScalesTheRollingSpringByItsCoefficient) {
  check_rolling(1e-3, 1e-3, 0.5e-3, kRRLinearKr, 2.5);
  check_rolling(0.8e-3, 1.2e-3, 0.8e-3 * 1.2e-3 / 2.0e-3, kRRLinearKr, 0.4);
  check_rolling(1e-3, 0, 1e-3, kRRLinearKr, 3.0);
  ContactParams p = test::law(1e8, 2.0, 0.5, 0.3);
  p.kr_ratio = 7;  // rrlinear's own rolling spring
  ContactKinematics k = kin(p, Vec3(0, 0, 1), 2e-6, 1e-3, 1e-3, 1e-7);
  k.dtheta = Vec3(1e-6, 0, 0);
  ContactHistory h;
  const double ks = kPi * 1e-6 * p.emod / 2e-3 / p.kratio;
  EXPECT_NEAR(norm(ContactLaws::eval(p, k, h).moment), ks * 0.25e-6 * 1e-6, 1e-12 * ks * 0.25e-12);
}

// Without twisting resistance (twist = 0, the default) a twist (relative rotation about n) is not resisted: no moment however long it lasts, and no shear.
TEST(ContactLaw, TwistProducesNoMoment) {
  const ContactParams p = test::law(1e8, 1.5, 0.5, 0.5);
  const Vec3 n = unit(Vec3(0.1, 0.2, -1));
  ContactKinematics k = kin(p, n, 1e-6, 1e-3, 1e-3, 1e-6);
  k.dtheta = 1e-6 * (500.0 * n);
  ContactHistory h;
  for (int s = 0; s < 1000; ++s) {
    const ContactOutput out = RRLinear::eval(p, k, h);
    // The only non-zero entries could come from rounding of the projection of a vector along n,
    // ~1e-16 of kr*|dtheta| per step: compare with 1e-12 of the moment the same rotation would build
    // up if it were bending (kr = ks Rbar^2, Rbar = R/2; cap mu_r Rbar Fn is far above this bound).
    const double kr = kPi * 1e-3 * 1e8 / 2 / 1.5 * 0.25e-6;
    EXPECT_LT(norm(out.moment), 1e-12 * kr * 5e-4 * (s + 1));
    EXPECT_FALSE(h.flags & kRolling);
  }
}

// Twisting resistance (twist > 0): a steady spin of 2 relative to 1 about n builds a moment on 1 along the spin at
// k_tw = ks Rbar^2 per radian, held at twist Rbar Fn once it gets there, with no bending moment and no shear; a
// spin back unloads it elastically by the same stiffness. Ball-ball (Rbar = R1 R2 / (R1 + R2)) and at a wall (R1).
namespace {
void check_twisting(double R1, double R2, double rbar_expect) {
  ContactParams p = test::law(1e8, 1.5, 0.5, 0.3);
  p.twist = 0.2;
  const double dt = 1e-7, d = 2e-6, spin = 30.0;  // rad/s
  const Vec3 n = unit(Vec3(0.3, -0.4, 1.0));
  const double kn = kn_formula(p.emod, R1, R2), ktw = kn / p.kratio * rbar_expect * rbar_expect;
  const double cap = p.twist * rbar_expect * kn * d, inc = ktw * spin * dt;
  const int nsat = static_cast<int>(std::ceil(cap / inc));
  ASSERT_GT(nsat, 20);  // set-up: an elastic stretch of several steps before the cap
  ContactKinematics k = kin(p, n, d, R1, R2, dt);
  k.dtheta = dt * spin * n;
  ContactHistory h;
  for (int s = 1; s <= nsat + 30; ++s) {
    const ContactOutput out = RRLinear::eval(p, k, h);
    // The increments are summed one step at a time: rounding of 1e-12 of the moment covers a few hundred steps.
    const double want = std::min(s * inc, cap);
    EXPECT_NEAR(dot(out.moment, n), want, 1e-12 * cap) << "step " << s;
    EXPECT_LT(norm(tangential(out.moment, n)), 1e-12 * cap) << "no bending moment from a spin";
    EXPECT_NEAR(h.slot[kTwistSlot], want, 1e-12 * cap);
    EXPECT_FALSE(h.flags & (kSliding | kRolling));
  }
  k.dtheta = -1.0 * k.dtheta;
  const ContactOutput back = RRLinear::eval(p, k, h);
  EXPECT_NEAR(dot(back.moment, n), cap - inc, 1e-12 * cap) << "a reversal unloads elastically";
}
}  // namespace

TEST(ContactLaw, TwistingResistanceBallBall) { check_twisting(0.8e-3, 1.2e-3, 0.8e-3 * 1.2e-3 / 2.0e-3); }
TEST(ContactLaw, TwistingResistanceWall) { check_twisting(1e-3, 0, 1e-3); }

// Adhesion (adhesion = c > 0): two touching balls pull on each other with F_a = c (2 r)^2, r the smaller radius,
// whatever the overlap: the normal force is kn delta - F_a, tensile at a small overlap and zero where kn delta = F_a.
// The shear cap stays mu_s kn delta (the elastic force), and a ball on a wall feels no pull. Exact to rounding: one
// product and one difference, 1e-12 of the forces.
TEST(ContactLaw, AdhesionPullsTouchingBallsOnly) {
  ContactParams p = test::law(1e8, 1.5, 0.5, 0.0);
  p.adhesion = 3e4;
  const double R1 = 0.8e-3, R2 = 1.2e-3, dt = 1e-7;
  const double fa = 4 * p.adhesion * R1 * R1, kn = kn_formula(p.emod, R1, R2);
  const Vec3 n = unit(Vec3(0.3, -0.4, 1.0));
  for (const double d : {0.1 * fa / kn, fa / kn, 5 * fa / kn}) {
    ContactKinematics k = kin(p, n, d, R1, R2, dt);
    k.vrel = Vec3(0.1, 0, 0) - dot(Vec3(0.1, 0, 0), n) * n;  // sliding: the shear force reaches its cap
    ContactHistory h;
    ContactOutput out;
    for (int s = 0; s < 2000; ++s) out = RRLinear::eval(p, k, h);
    // The force on 1 is -Fn n (n points from 1 to 2): a pull is along +n.
    EXPECT_NEAR(-dot(out.force, n), kn * d - fa, 1e-12 * fa) << "overlap " << d;
    EXPECT_NEAR(out.fn, kn * d, 1e-12 * kn * d) << "the elastic force, on which the caps stand";
    EXPECT_NEAR(norm(tangential(out.force, n)), p.mu_s * kn * d, 1e-12 * kn * d);
    const ContactKinematics wall = kin(p, n, d, R1, 0, dt);
    ContactHistory hw;
    EXPECT_NEAR(-dot(RRLinear::eval(p, wall, hw).force, n), wall.kn * d, 1e-12 * wall.kn * d) << "no pull at a wall";
  }
}

// ---------------------------------------------------------------------------------------------------
// No tension. (a) With beta_n > 0, a fast separation makes kn d - 2 beta sqrt(mc kn) vn negative: the
// total normal force is clamped to zero (exactly), while the linear force fn stays kn d > 0.
TEST(ContactLaw, DashpotNeverMakesTension) {
  const ContactParams p = test::law(1e8, 1.5, 0.5, 0.0, 0.3);
  const double R = 1e-3, d = 1e-7;
  const Vec3 n = unit(Vec3(1, -1, 0.5));
  ContactKinematics k = kin(p, n, d, R, R, 1e-7);
  const double kn = kPi * R * p.emod / 2;
  const double c = 2 * p.beta_n * std::sqrt(k.m1 * kn);
  // Separating: 2 moves away from 1 along n, fast enough that the dashpot exceeds the spring.
  const double vsep = 10 * kn * d / c;
  k.vrel = vsep * n;
  ContactHistory h;
  ContactOutput out = RRLinear::eval(p, k, h);
  EXPECT_EQ(dot(out.force, n), 0.0);
  EXPECT_NEAR(out.fn, kn * d, 1e-13 * kn * d);
  // Slowly separating: the dashpot only reduces the repulsion.
  k.vrel = 0.5 * kn * d / c * n;
  h = ContactHistory();
  out = RRLinear::eval(p, k, h);
  EXPECT_NEAR(-dot(out.force, n), 0.5 * kn * d, 1e-12 * kn * d);
}

// (b) A candidate contact with negative overlap is not evaluated by the force kernel: zero force, zero
// moment, and its history is dropped (the contact opened). Runs the real kernel on two balls.
TEST(ContactLaw, SeparatedCandidateCarriesNoForceAndLosesHistory) {
  const double R = 1e-3;
  std::vector<BallSpec> b(2);
  b[0].x = Vec3(0, 0, 0);
  b[1].x = Vec3(2 * R + 1e-7, 0, 0);  // gap of 1e-7 m: overlap < 0
  b[0].radius = b[1].radius = R;
  b[1].v = Vec3(0, 0.3, 0);
  b[0].w = Vec3(0, 0, 50);
  Particles p = make_particles(b);
  ContactList c(1);
  c.key = PairKeyView("key", 1);
  Kokkos::deep_copy(c.key, pair_key(0, 1));
  auto hi = Kokkos::create_mirror_view(c.i), hj = Kokkos::create_mirror_view(c.j);
  auto hfs = Kokkos::create_mirror_view(c.fs), hmr = Kokkos::create_mirror_view(c.mr);
  auto hfl = Kokkos::create_mirror_view(c.flags);
  hi(0) = 0;
  hj(0) = 1;
  hfs(0, 1) = 1e-3;  // stale history from an earlier touching period
  hmr(0, 2) = 1e-6;
  hfl(0) = kTouching | kSliding | kRolling;
  Kokkos::deep_copy(c.i, hi);
  Kokkos::deep_copy(c.j, hj);
  Kokkos::deep_copy(c.fs, hfs);
  Kokkos::deep_copy(c.mr, hmr);
  Kokkos::deep_copy(c.flags, hfl);
  ParamTableView table("table", 1, 1);
  auto ht = Kokkos::create_mirror_view(table);
  ht(0, 0) = test::law(1e8, 1.5, 0.5, 0.5, 0.2);
  Kokkos::deep_copy(table, ht);
  Domain dom;
  const OverlapStat st = compute_ball_forces(p, c, table, dom, 1e-7);
  EXPECT_LE(st.ratio, 0.0);
  auto fc = Kokkos::create_mirror_view_and_copy(HostSpace(), c.fc);
  auto mt = Kokkos::create_mirror_view_and_copy(HostSpace(), c.mt);
  auto mo = Kokkos::create_mirror_view_and_copy(HostSpace(), c.mo);
  auto fn = Kokkos::create_mirror_view_and_copy(HostSpace(), c.fn);
  auto fs = Kokkos::create_mirror_view_and_copy(HostSpace(), c.fs);
  auto mr = Kokkos::create_mirror_view_and_copy(HostSpace(), c.mr);
  auto fl = Kokkos::create_mirror_view_and_copy(HostSpace(), c.flags);
  EXPECT_EQ(fn(0), 0.0);
  EXPECT_EQ(fl(0), 0);
  for (int d = 0; d < 3; ++d) {
    EXPECT_EQ(fc(0, d), 0.0);
    EXPECT_EQ(mt(0, d), 0.0);
    EXPECT_EQ(mo(0, d), 0.0);
    EXPECT_EQ(fs(0, d), 0.0);
    EXPECT_EQ(mr(0, d), 0.0);
  }
}

// ---------------------------------------------------------------------------------------------------
// History rotates with the contact plane: rotate_into_plane keeps the magnitude and returns a vector
// tangent to the new normal. Random vectors and normals; 1e-14 relative is rounding of a few flops.
TEST(ContactLaw, RotateIntoPlaneKeepsMagnitudeAndIsTangent) {
  std::mt19937_64 rng(12345);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 1000; ++trial) {
    const Vec3 n0 = unit(Vec3(u(rng), u(rng), u(rng)));
    const Vec3 s = tangential(Vec3(u(rng), u(rng), u(rng)), n0);  // a stored tangent vector
    // The contact plane turns by a moderate angle.
    const Vec3 n1 = unit(n0 + 0.3 * Vec3(u(rng), u(rng), u(rng)));
    const Vec3 r = rotate_into_plane(s, n1);
    EXPECT_NEAR(norm(r), norm(s), 1e-14 * norm(s));
    EXPECT_LT(std::fabs(dot(r, n1)), 1e-14 * norm(s));
    // It keeps the direction of the tangential part of s (no spurious rotation within the plane).
    const Vec3 st = tangential(s, n1);
    EXPECT_NEAR(dot(r, st), norm(r) * norm(st), 1e-13 * norm(r) * norm(st));
    // Already tangent: unchanged.
    const Vec3 same = rotate_into_plane(s, n0);
    EXPECT_NEAR(norm(same - s), 0.0, 1e-14 * norm(s));
  }
  EXPECT_EQ(norm(rotate_into_plane(Vec3(), Vec3(0, 0, 1))), 0.0);
}

// Through the law: a loaded shear spring and rolling moment whose contact plane turns (no relative
// motion) keep their magnitudes and are carried into the new plane.
TEST(ContactLaw, HistoryFollowsTurningContactPlane) {
  const ContactParams p = test::law(1e8, 1.5, 0.5, 0.2);
  const double R = 1e-3, d = 3e-6, dt = 1e-7;
  Vec3 n(0, 0, 1);
  ContactKinematics k = kin(p, n, d, R, R, dt);
  ContactHistory h;
  k.vrel = Vec3(0.02, 0.01, 0);
  k.dtheta = dt * Vec3(-3, 4, 0);
  for (int s = 0; s < 5; ++s) RRLinear::eval(p, k, h);
  ASSERT_FALSE(h.flags & (kSliding | kRolling)) << "test set-up: stay elastic";
  const double fs0 = norm(h.fs), mr0 = norm(h.mr);
  ASSERT_GT(fs0, 0);
  ASSERT_GT(mr0, 0);
  k.vrel = Vec3();
  k.dtheta = Vec3();
  for (int s = 1; s <= 90; ++s) {
    const double a = s * kPi / 180;  // the pair rolls over: n turns 1 degree per step about y
    k.n = Vec3(std::sin(a), 0, std::cos(a));
    const ContactOutput out = RRLinear::eval(p, k, h);
    EXPECT_NEAR(norm(h.fs), fs0, 1e-12 * fs0);
    EXPECT_NEAR(norm(h.mr), mr0, 1e-12 * mr0);
    EXPECT_LT(std::fabs(dot(h.fs, k.n)), 1e-12 * fs0);
    EXPECT_LT(std::fabs(dot(h.mr, k.n)), 1e-12 * mr0);
    EXPECT_NEAR(norm(out.moment - h.mr), 0.0, 1e-15 * mr0);
  }
}

// ---------------------------------------------------------------------------------------------------
// Model extensions. Each has a closed form written out here; the law's tangent stiffness is
// also checked against a central difference of its own force, which is what the shear and rolling
// springs and the dashpot rely on. Central difference with h = 1e-5 overlap: truncation (h/d)^2 f'''/f'
// ~ 1e-10, rounding 1e-16 / 1e-5 ~ 1e-11; tolerance 1e-7 relative.
namespace {
NormalResponse normal_at(const ContactParams& p, double d, double r1, double r2) {
  return NormalElastic::response(p, kin(p, Vec3(0, 0, 1), d, r1, r2, 1e-7));
}
void expect_tangent_is_derivative(const ContactParams& p, double d, double r1, double r2) {
  const double h = 1e-5 * d;
  const double fd = (normal_at(p, d + h, r1, r2).fn - normal_at(p, d - h, r1, r2).fn) / (2 * h);
  const double k = normal_at(p, d, r1, r2).k;
  EXPECT_NEAR(k, fd, 1e-7 * fd) << "overlap " << d;
}
}  // namespace

// Hertz-Mindlin: Fn = kn d^(3/2) / dref^(1/2), dref = hertz_overlap * r; secant = kn at d = dref, tangent
// 1.5 kn there; Fn(4d) = 8 Fn(d). Pure arithmetic: 1e-13.
TEST(ContactLaw, HertzForceGrowsAsOverlapToThreeHalves) {
  ContactParams p = test::law(1e8, 1.5, 0.3, 0.0);
  p.hertz_overlap = 0.01;
  const double R = 1e-3, kn = kn_formula(p.emod, R, R), dref = 0.01 * R;
  for (double d : {1e-7, 3e-6, dref, 4e-5}) {
    const NormalResponse nr = normal_at(p, d, R, R);
    EXPECT_NEAR(nr.fn, kn * d * std::sqrt(d / dref), 1e-13 * kn * d);
    EXPECT_NEAR(nr.k, 1.5 * kn * std::sqrt(d / dref), 1e-13 * kn);
    expect_tangent_is_derivative(p, d, R, R);
  }
  EXPECT_NEAR(normal_at(p, dref, R, R).fn, kn * dref, 1e-13 * kn * dref);
  EXPECT_NEAR(normal_at(p, 4e-6, R, R).fn / normal_at(p, 1e-6, R, R).fn, 8.0, 1e-12);
  // At a wall r is the ball's radius.
  EXPECT_NEAR(normal_at(p, dref, R, 0).fn, kn_formula(p.emod, R, 0) * dref, 1e-13 * kn * dref);
  // The shear spring follows the tangent stiffness: one step of tangential velocity adds kt/kappa* v dt.
  ContactKinematics k = kin(p, Vec3(0, 0, 1), 4e-6, R, R, 1e-7);
  k.vrel = Vec3(0.01, 0, 0);
  ContactHistory h;
  RRLinear::eval(p, k, h);
  const double kt = 1.5 * kn * std::sqrt(4e-6 / dref);
  EXPECT_NEAR(norm(h.fs), kt / 1.5 * 0.01 * 1e-7, 1e-12 * kt / 1.5 * 1e-9);
  // The critical time step uses the stiffest contact up to the overlap guard.
  EXPECT_NEAR(NormalElastic::max_stiffness(p, R, R, 0.25 * R).kn, 1.5 * kn * std::sqrt(25.0), 1e-13 * kn);
  p.hertz_overlap = 0;
  EXPECT_EQ(NormalElastic::max_stiffness(p, R, R, 0.25 * R).kn, kn);
}

// hertz_mindlin, a law of its own, against Hertz's and Mindlin's formulas written out here from G and nu (PFC's hertz
// model's form: E* = G / (1 - nu), R* = R1 R2 / (R1 + R2)): Fn = 4/3 E* sqrt(R*) d^1.5, the tangent 2 E* a, a =
// sqrt(R* d), the shear spring Mindlin's 8 G* a, G* = G / (2 (2 - nu)). Pure arithmetic on a few doubles: 1e-13.
TEST(ContactLaw, HertzMindlinLawIsHertzsAndMindlins) {
  ContactParams p = test::law(1e8, 1.5, 0.3, 0.0);
  p.law = kHertzMindlin;
  p.shear_modulus = 25e9;  // glass
  p.poisson = 0.22;
  const double G = p.shear_modulus, nu = p.poisson, estar = G / (1 - nu), gstar = G / (2 * (2 - nu));
  for (const auto& [r1, r2] : {std::pair<double, double>{1e-3, 1e-3}, {1e-3, 0.6e-3}, {1e-3, 0.0}}) {
    const double rstar = r2 > 0 ? r1 * r2 / (r1 + r2) : r1;
    for (double d : {1e-8, 1e-7, 2e-6}) {
      ContactKinematics k = kin(p, Vec3(0, 0, 1), d, r1, r2, 1e-7);
      k.kn = ContactLaws::stiffness(p, r1, r2);
      const NormalResponse nr = NormalHertzMindlin::response(p, k);
      const double a = std::sqrt(rstar * d), fn = 4.0 / 3.0 * estar * std::sqrt(rstar) * std::pow(d, 1.5);
      EXPECT_NEAR(nr.fn, fn, 1e-13 * fn) << r2 << " " << d;
      EXPECT_NEAR(nr.k, 2 * estar * a, 1e-13 * estar * a);
      EXPECT_NEAR(nr.ks, 8 * gstar * a, 1e-13 * gstar * a);
      // One step of tangential velocity v loads the shear spring by ks v dt; the normal force is Hertz's.
      k.vrel = Vec3(0.01, 0, 0);
      ContactHistory h;
      const ContactOutput out = ContactLaws::eval(p, k, h);
      EXPECT_NEAR(norm(h.fs), 8 * gstar * a * 0.01 * 1e-7, 1e-12 * 8 * gstar * a * 1e-9);
      EXPECT_NEAR(-out.force.z, fn, 1e-13 * fn);
    }
    // The stiffest contact up to the overlap guard, for the time step: the tangents at that overlap.
    const MaxStiffness m = ContactLaws::max_stiffness(p, r1, r2, 0.01 * r1);
    EXPECT_NEAR(m.kn, 2 * estar * std::sqrt(rstar * 0.01 * r1), 1e-13 * m.kn);
    EXPECT_NEAR(m.ks, 8 * gstar * std::sqrt(rstar * 0.01 * r1), 1e-13 * m.ks);
  }
  // The rrlinear pair through the same table is RRLinear, bit for bit.
  ContactParams lin = test::law(1e8, 1.5, 0.3, 0.02);
  ContactKinematics k = kin(lin, unit(Vec3(1, 2, 2)), 1e-6, 1e-3, 0.9e-3, 1e-7);
  k.vrel = Vec3(0.01, -0.02, 0.005);
  k.dtheta = Vec3(1e-4, 0, 2e-4);
  ContactHistory h1, h2;
  const ContactOutput a = RRLinear::eval(lin, k, h1), b = ContactLaws::eval(lin, k, h2);
  EXPECT_EQ(std::memcmp(&a, &b, sizeof a), 0);
  EXPECT_EQ(std::memcmp(&h1.fs, &h2.fs, sizeof h1.fs), 0);
  EXPECT_EQ(std::memcmp(&h1.mr, &h2.mr, sizeof h1.mr), 0);
}

// Rough-surface compliance: bulk overlap d^2 / (d + 2 sigma). Soft while d << sigma (Fn ~ kn d^2 / 2 sigma),
// the smooth law shifted by 2 sigma once d >> sigma, and the stiffness ratio is d (d + 4 sigma) /
// (d + 2 sigma)^2: exactly 5/9 at d = sigma, above 0.9999 at d = 200 sigma.
TEST(ContactLaw, RoughSurfaceSoftensSmallOverlaps) {
  ContactParams p = test::law(1e8, 1.5, 0.3, 0.0);
  const double R = 1e-3, kn = kn_formula(p.emod, R, R), sigma = 1e-6;
  p.roughness = sigma / R;
  for (double d : {1e-8, 1e-7, sigma, 1e-5, 2e-4}) {
    const NormalResponse nr = normal_at(p, d, R, R);
    EXPECT_NEAR(nr.fn, kn * d * d / (d + 2 * sigma), 1e-13 * kn * d);
    EXPECT_LT(nr.fn, kn * d);  // always softer than smooth
    expect_tangent_is_derivative(p, d, R, R);
  }
  EXPECT_NEAR(normal_at(p, sigma, R, R).k / kn, 5.0 / 9.0, 1e-13);
  EXPECT_GT(normal_at(p, 200 * sigma, R, R).k / kn, 0.9999);
  EXPECT_LT(normal_at(p, 0.01 * sigma, R, R).k / kn, 0.01);
  // Large overlaps: the smooth force less kn * 2 sigma (to first order in sigma/d: 4 sigma^2/d = 2% of 2 sigma
  // at d = 200 sigma).
  const double d = 200 * sigma;
  EXPECT_NEAR(normal_at(p, d, R, R).fn, kn * (d - 2 * sigma), 0.03 * kn * 2 * sigma);
  // With Hertz as well: the bulk overlap goes through the Hertz law.
  p.hertz_overlap = 0.01;
  const double de = 3e-6 * 3e-6 / (3e-6 + 2 * sigma);
  EXPECT_NEAR(normal_at(p, 3e-6, R, R).fn, kn * de * std::sqrt(de / (0.01 * R)), 1e-13 * kn * de);
  expect_tangent_is_derivative(p, 3e-6, R, R);
}

// Slip-weakening friction: mu = mu_s (1 - wear (1 - exp(-s / (wear_slip r)))). Constant overlap and a steady
// tangential velocity: once sliding, the slip s is the tangential travel less the spring's elastic stretch,
// |fs| / ks (an identity of the incremental spring with a cap, to rounding: 1e-9 of the travel over
// ~3000 increments), and the force sits between mu(s_before) Fn and mu(s_after) Fn of the step.
TEST(ContactLaw, FrictionWeakensWithAccumulatedSlip) {
  ContactParams p = test::law(1e8, 1.5, 0.5, 0.0);
  p.wear = 0.4;
  p.wear_slip = 0.01;
  const double R = 1e-3, d = 5e-6, dt = 1e-7, v = 0.5;
  const Vec3 n(0, 0, 1);
  ContactKinematics k = kin(p, n, d, R, R, dt);
  k.vrel = Vec3(v, 0, 0);
  const double kn = kn_formula(p.emod, R, R), ks = kn / 1.5, fn = kn * d, sc = 0.01 * R;
  ContactHistory h;
  double travel = 0;
  for (int s = 0; s < 3000; ++s) {
    const double slip_before = h.slot[kSlipSlot];
    RRLinear::eval(p, k, h);
    travel += v * dt;
    const double fs = norm(h.fs);
    EXPECT_NEAR(h.slot[kSlipSlot], std::max(0.0, travel - fs / ks), 1e-9 * travel) << "step " << s;
    if (h.flags & kSliding) {
      const double mu_before = 0.5 * (1 - 0.4 * (1 - std::exp(-slip_before / sc)));
      const double mu_after = 0.5 * (1 - 0.4 * (1 - std::exp(-h.slot[kSlipSlot] / sc)));
      EXPECT_LE(fs, mu_before * fn * (1 + 1e-12));
      EXPECT_GE(fs, mu_after * fn * (1 - 1e-12));
    }
  }
  // 3000 steps of 5e-8 m: 1.5e-4 m of travel, 15 decay lengths: the residual mu_s (1 - wear) = 0.3.
  EXPECT_NEAR(norm(h.fs) / fn, 0.3, 1e-6);
  // The formula of the law at one decay length.
  EXPECT_NEAR(TangentialCoulomb::friction(p, R, sc), 0.5 * (1 - 0.4 * (1 - std::exp(-1.0))), 1e-15);
  // Without wear the slip is not tracked and the cap is mu_s Fn.
  p.wear = 0;
  ContactHistory h0;
  for (int s = 0; s < 3000; ++s) RRLinear::eval(p, k, h0);
  EXPECT_EQ(h0.slot[kSlipSlot], 0.0);
  EXPECT_NEAR(norm(h0.fs), 0.5 * fn, 1e-12 * fn);
}

// The wear law's exponential, written with IEEE's exactly rounded operations alone so that a GPU gives the CPU's
// bits (CUDA's exp and glibc's differ in the last ulp: Reference.PeriodicCell's wear row moved by 5e-4 on an
// H100). Against glibc's exp, itself within an ulp of the truth: at most 2 ulp apart over the whole range, the
// subnormal results included, and the special values as the library gives them.
TEST(ContactLaw, PortableExpIsWithinTwoUlpOfTheLibrarysOverItsWholeRange) {
  auto ulps = [](double a, double b) {
    std::int64_t ia, ib;
    std::memcpy(&ia, &a, sizeof a);
    std::memcpy(&ib, &b, sizeof b);
    return ia > ib ? ia - ib : ib - ia;  // both positive: the bit patterns order as the values
  };
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> wide(-745.0, 709.7), near(-1.0, 1.0);
  std::int64_t worst = 0;
  double at = 0;
  for (int k = 0; k < 400000; ++k) {
    const double x = k % 2 ? wide(rng) : near(rng);
    const std::int64_t d = ulps(dem::kc::exp(x), std::exp(x));
    if (d > worst) worst = d, at = x;
  }
  EXPECT_LE(worst, 2) << "at x = " << at;
  EXPECT_EQ(dem::kc::exp(0.0), 1.0);
  EXPECT_EQ(dem::kc::exp(-1e-300), 1.0);
  EXPECT_EQ(dem::kc::exp(-800.0), 0.0);
  EXPECT_EQ(dem::kc::exp(-std::numeric_limits<double>::infinity()), 0.0);
  EXPECT_EQ(dem::kc::exp(709.79), std::numeric_limits<double>::infinity());
  EXPECT_EQ(dem::kc::exp(std::numeric_limits<double>::infinity()), std::numeric_limits<double>::infinity());
  EXPECT_TRUE(std::isnan(dem::kc::exp(std::nan(""))));
  EXPECT_LE(ulps(dem::kc::exp(-740.0), std::exp(-740.0)), 2);  // a subnormal result
}
