#include "kernels/core/particles.hpp"

namespace dem {

Particles::Particles(int count)
    : x("dem::particles::x", count), v("dem::particles::v", count), w("dem::particles::w", count),
      f("dem::particles::f", count), m("dem::particles::m", count), x_ref("dem::particles::x_ref", count),
      radius("dem::particles::radius", count), mass("dem::particles::mass", count),
      inertia("dem::particles::inertia", count), gid("dem::particles::gid", count),
      specimen("dem::particles::specimen", count), material("dem::particles::material", count), n(count) {}

namespace {
template <class View>
void permute_view(View& a, const IndexView& perm) {
  View out(Kokkos::view_alloc(Kokkos::WithoutInitializing, a.label()), a.extent(0));
  const int ncomp = static_cast<int>(a.extent(1));
  Kokkos::parallel_for("dem::particles::permute", RangePolicy(0, a.extent(0)), KOKKOS_LAMBDA(const int k) {
    for (int d = 0; d < ncomp; ++d) out(k, d) = a(perm(k), d);
  });
  a = out;
}
template <class View>
void permute_scalar(View& a, const IndexView& perm) {
  View out(Kokkos::view_alloc(Kokkos::WithoutInitializing, a.label()), a.extent(0));
  Kokkos::parallel_for("dem::particles::permute", RangePolicy(0, a.extent(0)),
                       KOKKOS_LAMBDA(const int k) { out(k) = a(perm(k)); });
  a = out;
}
}  // namespace

void Particles::permute(const IndexView& perm) {
  for (Vec3View* a : {&x, &v, &w, &f, &m, &x_ref}) permute_view(*a, perm);
  for (ScalarView* a : {&radius, &mass, &inertia}) permute_scalar(*a, perm);
  permute_scalar(gid, perm);
  permute_scalar(specimen, perm);
  permute_scalar(material, perm);
}

std::uint32_t Particles::gid_bound() const {
  std::uint32_t mx = 0;
  auto g = gid;
  Kokkos::parallel_reduce("dem::particles::gid_max", RangePolicy(0, n),
      KOKKOS_LAMBDA(const int i, std::uint32_t& acc) { if (g(i) > acc) acc = g(i); },
      Kokkos::Max<std::uint32_t>(mx));
  return n > 0 ? mx + 1 : 0;
}

}  // namespace dem
