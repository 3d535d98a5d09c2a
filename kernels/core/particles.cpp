#include "kernels/core/particles.hpp"

#include <utility>

#include "kernels/core/buffers.hpp"

namespace dem {

Particles::Particles(int count)
    : x("dem::particles::x", count), v("dem::particles::v", count), w("dem::particles::w", count),
      f("dem::particles::f", count), m("dem::particles::m", count), x_ref("dem::particles::x_ref", count),
      radius("dem::particles::radius", count), mass("dem::particles::mass", count),
      inertia("dem::particles::inertia", count), gid("dem::particles::gid", count),
      specimen("dem::particles::specimen", count), material("dem::particles::material", count), n(count) {}

namespace {
/// a's rows in perm's order, into `spare` (made of a's size where it is not), which then swaps with a.
template <class View>
void permute_view(View& a, View& spare, const IndexView& perm) {
  same_size(spare, a.extent(0), a.label().c_str());
  const View in = a, out = spare;
  const int ncomp = static_cast<int>(a.extent(1));
  Kokkos::parallel_for("dem::particles::permute", RangePolicy(0, a.extent(0)), KOKKOS_LAMBDA(const int k) {
    for (int d = 0; d < ncomp; ++d) out(k, d) = in(perm(k), d);
  });
  std::swap(a, spare);
}
template <class View>
void permute_scalar(View& a, View& spare, const IndexView& perm) {
  same_size(spare, a.extent(0), a.label().c_str());
  const View in = a, out = spare;
  Kokkos::parallel_for("dem::particles::permute", RangePolicy(0, a.extent(0)),
                       KOKKOS_LAMBDA(const int k) { out(k) = in(perm(k)); });
  std::swap(a, spare);
}
}  // namespace

void Particles::permute(const IndexView& perm, Particles& spare) {
  Vec3View* mine[] = {&x, &v, &w, &f, &m, &x_ref};
  Vec3View* theirs[] = {&spare.x, &spare.v, &spare.w, &spare.f, &spare.m, &spare.x_ref};
  for (int k = 0; k < 6; ++k) permute_view(*mine[k], *theirs[k], perm);
  ScalarView* mine_s[] = {&radius, &mass, &inertia};
  ScalarView* theirs_s[] = {&spare.radius, &spare.mass, &spare.inertia};
  for (int k = 0; k < 3; ++k) permute_scalar(*mine_s[k], *theirs_s[k], perm);
  permute_scalar(gid, spare.gid, perm);
  permute_scalar(specimen, spare.specimen, perm);
  permute_scalar(material, spare.material, perm);
  spare.n = n;
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
