#include "kernels/motion/integrate.hpp"

#include "kernels/core/buffers.hpp"
#include "kernels/core/reduce.hpp"
#include "kernels/neighbor/history_remap.hpp"

namespace dem {

namespace {

/// A measured step's |F + m g| and kinetic energy of the particle with gid g (none for a gid without one, or, in a
/// batch, of a specimen whose step is not measured).
struct MeasuredByGid {
  Real2View measured;
  ConstIndexView gid2local;
  SpecimenTable spec;
  ConstIndexView owner;
  KOKKOS_INLINE_FUNCTION void operator()(const int g, int, Real (*vals)[2]) const {
    const int i = gid2local(g);
    if (i < 0 || (spec.batched() && !spec(owner(i)).integ.measure)) return;
    vals[0][0] = measured(i, 0);
    vals[0][1] = measured(i, 1);
  }
};

Leapfrog leapfrog(Particles& p, const SpecimenTable& spec, const Gather& gather, const IntegrateScratch& scratch) {
  return Leapfrog{p.x, p.v, p.w, p.x_ref, p.mass, p.inertia, p.radius, gather, spec, p.specimen,
                  scratch.measured};
}

}  // namespace

void IntegrateScratch::renew(const Particles& p) {
  same_size(measured, static_cast<std::size_t>(p.n), "dem::integrate::measured");
  gid_to_local(p, gid2local);
}

void integrate_to(Particles& p, const Domain& dom, const IntegrateParams& prm, const Gather& gather,
                  const IntegrateScratch& scratch, Real* values) {
  SpecimenTable one;
  one.one.dom = dom;
  one.one.integ = prm;
  integrate_to(p, one, gather, scratch, values);
}

void integrate_to(Particles& p, const SpecimenTable& one, const Gather& gather, const IntegrateScratch& scratch,
                  Real* values) {
  const IntegrateParams& prm = one.one.integ;
  deterministic_reduce_lanes_to<Leapfrog::kSums, Leapfrog::kMaxima, Leapfrog::W>(
      "dem::integrate::leapfrog", p.n, leapfrog(p, one, gather, scratch), values);
  if (!prm.measure) return;
  // The gids' order, not the particles': it changes no bit where a rebuild reorders them.
  deterministic_reduce_lanes_to<2, 0, 1>("dem::integrate::measured", static_cast<int>(scratch.gid2local.extent(0)),
                                         MeasuredByGid{scratch.measured, scratch.gid2local, one, p.specimen}, values);
}

void integrate_batch_to(Particles& p, const SpecimenParamsView& specimens, const SegmentedTree& tree,
                        const Gather& gather, const IntegrateScratch& scratch, Real* values, int stride, bool measured) {
  SpecimenTable many;
  many.many = specimens;
  segmented_reduce_lanes_to<Leapfrog::kSums, Leapfrog::kMaxima, Leapfrog::W>(
      "dem::integrate::leapfrog", tree, leapfrog(p, many, gather, scratch), values, stride);
  if (!measured) return;
  segmented_reduce_lanes_to<2, 0, 1>("dem::integrate::measured", tree,
                                     MeasuredByGid{scratch.measured, scratch.gid2local, many, p.specimen}, values, stride);
}

void gather_forces(const Particles& p, const Gather& gather) {
  auto f = p.f, m = p.m;
  Kokkos::parallel_for("dem::integrate::gather_forces", RangePolicy(0, p.n), KOKKOS_LAMBDA(const int i) {
    Vec3 fi, mi;
    gather(i, fi, mi);
    store(f, i, fi);
    store(m, i, mi);
  });
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

StepStats integrate(Particles& p, const Domain& dom, const IntegrateParams& prm, const Gather& gather) {
  IntegrateScratch scratch;
  scratch.renew(p);
  integrate_to(p, dom, prm, gather, scratch, reduce_root().data());
  gather_forces(p, gather);
  Real values[Leapfrog::kValues];
  read_root(values, Leapfrog::kValues);
  StepStats st = step_stats(values);
  if (values[2] > 0) st.bad = non_finite_particle(p);
  return st;
}

}  // namespace dem
