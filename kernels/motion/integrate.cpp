#include "kernels/motion/integrate.hpp"

#include "kernels/core/reduce.hpp"

namespace dem {

StepStats integrate(Particles& p, const IntegrateParams& prm, const Gather& gather) {
  const Leapfrog lf{p.x, p.v, p.w, p.f, p.m, p.x_ref, p.mass, p.inertia, p.radius, gather, prm};
  Real sums[Leapfrog::kValues];
  deterministic_reduce_lanes<Leapfrog::kSums, Leapfrog::kMaxima, Leapfrog::W>("dem::integrate::leapfrog", p.n, lf, sums);
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
