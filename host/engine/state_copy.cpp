#include "host/engine/state_copy.hpp"

#include <algorithm>
#include <type_traits>
#include <utility>

#include "host/engine/simulation.hpp"

namespace dem {

namespace {

/// Copies the first n rows of the device View `d` into the kept buffer `h`, which is replaced by one of n and a
/// quarter more where it is short: a list that grows a little between records then keeps its buffer. One copy a
/// View where its first rows are contiguous; a LayoutLeft 3-vector's are three columns, one copy each.
template <class H, class D>
void copy_rows(H& h, const D& d, int n) {
  if (static_cast<int>(h.extent(0)) < n)
    h = H(Kokkos::view_alloc(Kokkos::WithoutInitializing, "dem::state_copy"), static_cast<std::size_t>(n + n / 4));
  const auto rows = std::make_pair(0, n);
  if constexpr (H::rank == 1) {
    Kokkos::deep_copy(Kokkos::subview(h, rows), Kokkos::subview(d, rows));
  } else if constexpr (std::is_same<typename H::array_layout, Kokkos::LayoutRight>::value) {
    Kokkos::deep_copy(Kokkos::subview(h, rows, Kokkos::ALL()), Kokkos::subview(d, rows, Kokkos::ALL()));
  } else {
    for (int c = 0; c < static_cast<int>(h.extent(1)); ++c)
      Kokkos::deep_copy(Kokkos::subview(h, rows, c), Kokkos::subview(d, rows, c));
  }
}

void copy_list(ContactCopy::List& h, const ContactList& d) {
  h.n = d.n;
  copy_rows(h.i, d.i, d.n);
  copy_rows(h.j, d.j, d.n);
  copy_rows(h.fc, d.fc, d.n);
  copy_rows(h.fn, d.fn, d.n);
}

}  // namespace

void copy_state(Simulation& sim, bool contacts, ContactCopy& into) {
  const Particles& p = sim.particles();
  into.n = p.n;
  copy_rows(into.gid, p.gid, p.n);
  copy_rows(into.x, p.x, p.n);
  const FacetMesh& mesh = sim.mesh();
  copy_rows(into.node_x, mesh.node_x, mesh.nnode);
  if (into.ntri != mesh.ntri) {
    into.ntri = mesh.ntri;
    copy_rows(into.tri, mesh.tri, mesh.ntri);
    const Membrane& m = sim.membrane();
    copy_rows(into.fixed, m.fixed, m.nnode);
  }
  into.contacts = contacts;
  into.domain = sim.domain();
  if (!contacts) return;
  copy_rows(into.radius, p.radius, p.n);
  copy_list(into.balls, sim.ball_contacts());
  copy_list(into.walls, sim.wall_contacts());
  const WallSet& walls = sim.walls();
  into.nwalls = walls.n;
  copy_rows(into.wall_kind, walls.kind, walls.n);
  copy_rows(into.wall_point, walls.point, walls.n);
  copy_rows(into.wall_normal, walls.normal, walls.n);
  copy_rows(into.wall_radius, walls.radius, walls.n);
}

std::vector<Vec3> centres_by_gid(const ContactCopy& c) {
  std::vector<Vec3> x(static_cast<std::size_t>(c.n));
  for (int i = 0; i < c.n; ++i) x[c.gid(i)] = load(c.x, i);
  return x;
}

std::shared_ptr<const ContactCopy> StateCopies::take(Simulation& sim, bool contacts) {
  // A copy held only here is one no record's work reads any more.
  auto free = std::find_if(kept_.begin(), kept_.end(), [](const auto& c) { return c.use_count() == 1; });
  if (free == kept_.end()) free = kept_.insert(kept_.end(), std::make_shared<ContactCopy>());
  copy_state(sim, contacts, **free);
  return *free;
}

}  // namespace dem
