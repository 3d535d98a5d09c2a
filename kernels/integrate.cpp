#include "integrate.hpp"

#include "reduce.hpp"

namespace dem {

namespace {

struct Leapfrog {
  Vec3View x, v, w, f, m;
  ConstVec3View x_ref;
  ConstScalarView mass, inertia, radius;
  Gather gather;
  IntegrateParams prm;

  /// Advances particle i; vals = {|F + m g|, kinetic energy, non-finite flag, displacement^2 since rebuild,
  /// (move this step / radius)^2}.
  KOKKOS_INLINE_FUNCTION void operator()(const int i, Real* vals) const {
    const Real mi = mass(i), ii = inertia(i);
    Vec3 fc, moment;
    gather(i, fc, moment);
    store(f, i, fc);
    store(m, i, moment);
    const Vec3 force = fc + mi * prm.gravity;
    Vec3 vi = load(v, i), wi = load(w, i);
    const Vec3 x0 = load(x, i);
    const Real a = prm.dt / (mi * prm.mass_scale), b = prm.dt / (ii * prm.mass_scale);
    const Vec3 vd = damped_velocity(prm, vi, x0);
    vi = vi + a * Vec3(force.x + local_damping(force.x, vd.x, prm.alpha), force.y + local_damping(force.y, vd.y, prm.alpha),
                       force.z + local_damping(force.z, vd.z, prm.alpha));
    wi = wi + b * Vec3(moment.x + local_damping(moment.x, wi.x, prm.alpha),
                       moment.y + local_damping(moment.y, wi.y, prm.alpha),
                       moment.z + local_damping(moment.z, wi.z, prm.alpha));
    const Vec3 xi = x0 + prm.dt * vi;
    store(v, i, vi);
    store(w, i, wi);
    store(x, i, xi);
    if (prm.measure) {
      vals[0] = norm(force);
      vals[1] = Real(0.5) * (mi * norm2(vi) + ii * norm2(wi));
    }
    vals[2] = (kc::isfinite(xi.x) && kc::isfinite(xi.y) && kc::isfinite(xi.z)) ? Real(0) : Real(1);
    vals[3] = norm2(xi - load(x_ref, i));
    vals[4] = norm2(vi) * (prm.dt * prm.dt) / (radius(i) * radius(i));
  }
};

}  // namespace

StepStats integrate(Particles& p, const IntegrateParams& prm, const Gather& gather) {
  const Leapfrog lf{p.x, p.v, p.w, p.f, p.m, p.x_ref, p.mass, p.inertia, p.radius, gather, prm};
  Real sums[5];
  deterministic_reduce<3, 2>("dem::integrate::leapfrog", p.n,
                             KOKKOS_LAMBDA(const int i, Real* vals) { lf(i, vals); }, sums);
  StepStats st;
  st.unbalanced = sums[0];
  st.kinetic = sums[1];
  st.max_disp2 = sums[3];
  st.max_move2 = sums[4];
  auto x = p.x;
  if (sums[2] > 0) {
    int bad = -1;
    Kokkos::parallel_reduce("dem::integrate::find_bad", RangePolicy(0, p.n),
        KOKKOS_LAMBDA(const int i, int& acc) {
          const Vec3 xi = load(x, i);
          if (!(kc::isfinite(xi.x) && kc::isfinite(xi.y) && kc::isfinite(xi.z)) && i > acc) acc = i;
        }, Kokkos::Max<int>(bad));
    st.bad = bad;
  }
  return st;
}

}  // namespace dem
