#pragma once
/// Centred-difference (leapfrog) integration as in PFC, with gravity and local (Cundall) damping:
///   F_d = -alpha |F| sign(v), component-wise on forces and on moments (PFC manual; sign(0) = 0; v may be
///   taken about a mean flow, IntegrateParams::about_flow),
///   v(t + dt/2) = v(t - dt/2) + (F + F_d) / m dt,   x(t + dt) = x(t) + v(t + dt/2) dt.
/// Density scaling multiplies inertial mass and moment of inertia (not weight) by `mass_scale`.
#include "kernels/contact/accumulate.hpp"
#include "kernels/core/reduce.hpp"
#include "kernels/core/particles.hpp"
#include "kernels/core/specimen.hpp"
#include "kernels/core/vec3.hpp"

namespace dem {


/// Per-step sums over particles, for the unbalanced-force ratio and energy.
struct StepStats {
  Real unbalanced = 0;    ///< sum |F + m g| before damping (N), on measured steps
  Real kinetic = 0;       ///< translational + rotational kinetic energy (J), at t + dt/2, on measured steps
  Real max_disp2 = 0;     ///< largest squared displacement since the last rebuild (m^2)
  Real max_move2 = 0;     ///< largest (distance moved this step / radius)^2
  Real max_step2 = 0;     ///< largest squared distance moved this step (m^2)
  int bad = -1;           ///< a particle with a non-finite position, or -1
};

/// Local damping of one component: -alpha |F| sign(v), lane by lane for a pack (sign(0) = sign(NaN) = 0).
template <class T>
KOKKOS_INLINE_FUNCTION T local_damping(const T& f, const T& v, Real alpha) {
  const T s = select(v > T(0), T(1), select(v < T(0), T(-1), T(0)));
  return T(-alpha) * kc::fabs(f) * s;
}

/// Each component of F plus its local damping against v.
template <class T>
KOKKOS_INLINE_FUNCTION Vec3T<T> damped(const Vec3T<T>& f, const Vec3T<T>& v, Real alpha) {
  return Vec3T<T>(f.x + local_damping(f.x, v.x, alpha), f.y + local_damping(f.y, v.y, alpha),
                  f.z + local_damping(f.z, v.z, alpha));
}

/// The velocity local damping is measured against (IntegrateParams::about_flow): v, or v less the mean flow at x.
template <class T>
KOKKOS_INLINE_FUNCTION Vec3T<T> damped_velocity(const IntegrateParams& prm, const Vec3T<T>& v, const Vec3T<T>& x) {
  if (!prm.about_flow) return v;
  const Vec3T<T> d = x - broadcast<T>(prm.flow_origin);
  return v - Vec3T<T>(prm.flow_rate.x * d.x, prm.flow_rate.y * d.y, prm.flow_rate.z * d.z);
}

/// The step of W particles at once, as the lanes of a pack (kContactLanes; one on a GPU): each one's gather, then
/// the leapfrog update. Every lane does the IEEE operations of one particle, so the lanes change no bit. The gathered
/// force and moment are not stored: only output reads them, and gather_forces makes them again, bit for bit.
struct Leapfrog {
  /// A particle's values: {|F + m g|, kinetic energy, non-finite flag | displacement^2 since rebuild,
  /// (move this step / radius)^2, move this step^2}; the first kSums are summed, the last kMaxima maximised.
  /// On a measured step the first two are also written to `measured` (row: the particle), and their sums in gid order
  /// (integrate_to's second tree) replace this tree's: they do not depend on the particles' order, which a rebuild
  /// changes.
  static constexpr int kSums = 3, kMaxima = 3, kValues = kSums + kMaxima;
  static constexpr int W = kContactLanes;
  Vec3View x, v, w;
  Vec3View x_ref;        ///< moved with its particle where the particle is wrapped into the periodic cell
  ConstScalarView mass, inertia, radius;
  Gather gather;
  SpecimenTable spec;
  ConstIndexView owner;  ///< the particles' specimens (Particles::specimen), read where spec is a batch's
  Real2View measured;

  /// Particles i0 .. i0 + count - 1 (count <= W); vals[k] gets particle i0 + k's values.
  KOKKOS_INLINE_FUNCTION void operator()(const int i0, const int count, Real (*vals)[kValues]) const {
    using T = ContactPack;
    // A group of W particles lies in one specimen: the blocks of a batch's reduction start at its specimens' first.
    const int own = spec.batched() ? owner(i0) : 0;
    const SpecimenParams& sp = spec(own);
    const IntegrateParams& prm = sp.integ;
    // Lanes past count repeat the last particle; their results are not stored.
    int id[W];
    Vec3 fk[W], mk[W];
    TRIAXDEM_UNROLL_LANES
    for (int k = 0; k < W; ++k) {
      id[k] = i0 + (k < count ? k : count - 1);
      gather(id[k], fk[k], mk[k]);
    }
    const bool full = count == W;
    const T mi = from_lanes<T>([&](int k) { return mass(id[k]); });
    const T ii = from_lanes<T>([&](int k) { return inertia(id[k]); });
    const T ri = from_lanes<T>([&](int k) { return radius(id[k]); });
    const Vec3T<T> fc = vec_of_lanes<T>([&](int k) { return fk[k]; });
    const Vec3T<T> moment = vec_of_lanes<T>([&](int k) { return mk[k]; });
    const Vec3T<T> force = fc + mi * broadcast<T>(prm.gravity);
    const Vec3T<T> x0 = load_lanes<T>(x, i0, id, full);
    Vec3T<T> vi = load_lanes<T>(v, i0, id, full), wi = load_lanes<T>(w, i0, id, full);
    const T a = prm.dt / (mi * prm.mass_scale), b = prm.dt / (ii * prm.mass_scale);
    vi = vi + a * damped(force, damped_velocity(prm, vi, x0), prm.alpha);
    wi = wi + b * damped(moment, wi, prm.alpha);
    Vec3T<T> xi = x0 + T(prm.dt) * vi;
    const Vec3T<T> shift = step_wrap(spec.dom(own), xi);
    const auto put_all = [&](auto at) {
      put(v, at, vi);
      put(w, at, wi);
      put(x, at, xi);
    };
    if (full) {
      put_all(PackRows{i0});
    } else {
      TRIAXDEM_UNROLL_LANES
      for (int k = 0; k < W; ++k)
        if (k < count) put_all(LaneRow{id[k], k});
    }
    TRIAXDEM_UNROLL_LANES
    for (int k = 0; k < W; ++k) {
      if (k == count) break;
      const Vec3 s = lane(shift, k);
      if (s.x != 0 || s.y != 0 || s.z != 0) store(x_ref, id[k], load(x_ref, id[k]) + s);
    }
    const T unbalanced = prm.measure ? norm(force) : T(0);
    const T kinetic = prm.measure ? T(Real(0.5)) * (mi * norm2(vi) + ii * norm2(wi)) : T(0);
    const T disp2 = norm2(xi - load_lanes<T>(x_ref, i0, id, full));
    const T step2 = norm2(vi) * T(prm.dt * prm.dt);
    const T move2 = step2 / (ri * ri);
    TRIAXDEM_UNROLL_LANES
    for (int k = 0; k < W; ++k) {
      if (k == count) break;
      const Vec3 xk = lane(xi, k);
      vals[k][0] = lane(unbalanced, k);
      vals[k][1] = lane(kinetic, k);
      if (prm.measure) {
        measured(id[k], 0) = vals[k][0];
        measured(id[k], 1) = vals[k][1];
      }
      vals[k][2] = (kc::isfinite(xk.x) && kc::isfinite(xk.y) && kc::isfinite(xk.z)) ? Real(0) : Real(1);
      vals[k][3] = lane(disp2, k);
      vals[k][4] = lane(move2, k);
      vals[k][5] = lane(step2, k);
    }
  }
};

/// What a step's integration keeps between steps: the measured step's values per particle (Leapfrog::measured) and
/// the map from gid to the particles' present order to sum them by.
struct IntegrateScratch {
  Real2View measured;
  IndexView gid2local;
  /// For the particles' present order and count (at a rebuild: a step allocates nothing).
  void renew(const Particles& p);
};

/// Completes each particle's force and moment (gather), advances all particles one step in `dom` (wrapped into it
/// where periodic) and stores the forces and moments in p.f, p.m (gather_forces). Returns the step's sums
/// (deterministic: fixed-order reduction).
StepStats integrate(Particles& p, const Domain& dom, const IntegrateParams& prm, const Gather& gather);
/// The same, with the step's Leapfrog::kValues values left in device memory at `values` (step_stats reads them).
void integrate_to(Particles& p, const Domain& dom, const IntegrateParams& prm, const Gather& gather,
                  const IntegrateScratch& scratch, Real* values);
/// The same for the one specimen of `one` (SpecimenTable: its cell by value or in device memory, one.one.integ).
void integrate_to(Particles& p, const SpecimenTable& one, const Gather& gather, const IntegrateScratch& scratch,
                  Real* values);
/// The same for the specimens of a batch at once (specimens(s) holding specimen s's particles and time integration,
/// `tree` segmented by their particles, which are its gids too): specimen s's values go to values[s * stride + q],
/// bit for bit those of integrate_to on the specimen alone. `measured`: some specimen's step is measured.
void integrate_batch_to(Particles& p, const SpecimenParamsView& specimens, const SegmentedTree& tree,
                        const Gather& gather, const IntegrateScratch& scratch, Real* values, int stride, bool measured);
/// Each particle's force and moment of the contact results in `gather` (the last step's), to p.f and p.m: the same
/// bits the step's leapfrog summed, for output, which alone reads them.
void gather_forces(const Particles& p, const Gather& gather);
/// The statistics in a step's values; `bad` is left at -1 (non_finite_particle finds it where values[2] > 0).
StepStats step_stats(const Real* values);
/// The highest index of a particle with a non-finite position among [first, first + count) (count < 0: all), or -1.
int non_finite_particle(const Particles& p, int first = 0, int count = -1);

}  // namespace dem
