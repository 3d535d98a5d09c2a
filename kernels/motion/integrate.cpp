#include "kernels/motion/integrate.hpp"

#include "kernels/core/reduce.hpp"

namespace dem {

void integrate_to(Particles& p, const IntegrateParams& prm, const Gather& gather, Real* values) {
  SpecimenTable one;
  one.one.integ = prm;
  const Leapfrog lf{p.x, p.v, p.w, p.f, p.m, p.x_ref, p.mass, p.inertia, p.radius, gather, one, p.specimen};
  deterministic_reduce_lanes_to<Leapfrog::kSums, Leapfrog::kMaxima, Leapfrog::W>("dem::integrate::leapfrog", p.n, lf,
                                                                                 values);
}

void integrate_batch_to(Particles& p, const SpecimenParamsView& specimens, const SegmentedTree& tree,
                        const Gather& gather, Real* values, int stride) {
  SpecimenTable many;
  many.many = specimens;
  const Leapfrog lf{p.x, p.v, p.w, p.f, p.m, p.x_ref, p.mass, p.inertia, p.radius, gather, many, p.specimen};
  segmented_reduce_lanes_to<Leapfrog::kSums, Leapfrog::kMaxima, Leapfrog::W>("dem::integrate::leapfrog", tree, lf,
                                                                             values, stride);
}

StepStats step_stats(const Real* values) {
  StepStats st;
  st.unbalanced = values[0];
  st.kinetic = values[1];
  st.max_disp2 = values[3];
  st.max_move2 = values[4];
  st.max_step2 = values[5];
  return st;
}

int non_finite_particle(const Particles& p, int first, int count) {
  auto x = p.x;
  int bad = -1;
  Kokkos::parallel_reduce("dem::integrate::find_bad", RangePolicy(first, count < 0 ? p.n : first + count),
      KOKKOS_LAMBDA(const int i, int& acc) {
        const Vec3 xi = load(x, i);
        if (!(kc::isfinite(xi.x) && kc::isfinite(xi.y) && kc::isfinite(xi.z)) && i > acc) acc = i;
      }, Kokkos::Max<int>(bad));
  return bad;
}

StepStats integrate(Particles& p, const IntegrateParams& prm, const Gather& gather) {
  integrate_to(p, prm, gather, reduce_root().data());
  Real values[Leapfrog::kValues];
  read_root(values, Leapfrog::kValues);
  StepStats st = step_stats(values);
  if (values[2] > 0) st.bad = non_finite_particle(p);
  return st;
}

}  // namespace dem
