/// The contacts of a state, gathered for the micromechanics (host/engine/micro.hpp): from a running simulation or from
/// a saved snapshot, and back into a snapshot's contact table.
#include <algorithm>
#include <stdexcept>
#include <string>

#include "host/engine/builder.hpp"
#include "host/io/io_hdf5.hpp"
#include "host/engine/micro.hpp"
#include "host/engine/simulation.hpp"

namespace dem {

namespace {

/// A touching contact of ball a along `d` (from a's centre to the other centre or to the contact point),
/// from the force on a (`fc_on_a`) and the linear normal force: the force on b is the reaction.
ContactRecord record(int a, const Vec3& d, const Vec3& fc_on_a, Real fn) {
  ContactRecord c;
  c.a = a;
  c.branch = d;
  c.normal = (1 / norm(d)) * d;
  const Vec3 f = -1.0 * fc_on_a;
  c.fn = fn;
  c.ft = f - dot(f, c.normal) * c.normal;
  return c;
}

}  // namespace

ContactSet contact_set(Simulation& sim) {
  Particles& p = sim.particles();
  ContactSet s;
  const HostParticles h = to_host_by_gid(p);
  s.x = h.x;
  auto gid = Kokkos::create_mirror_view_and_copy(HostSpace(), p.gid);
  auto rad = Kokkos::create_mirror_view_and_copy(HostSpace(), p.radius);
  s.radius.resize(p.n);
  for (int i = 0; i < p.n; ++i) s.radius[gid(i)] = rad(i);
  const Domain& dom = sim.domain();

  const ContactList& bc = sim.ball_contacts();
  auto ci = Kokkos::create_mirror_view_and_copy(HostSpace(), bc.i);
  auto cj = Kokkos::create_mirror_view_and_copy(HostSpace(), bc.j);
  auto fc = Kokkos::create_mirror_view_and_copy(HostSpace(), bc.fc);
  auto fn = Kokkos::create_mirror_view_and_copy(HostSpace(), bc.fn);
  for (int k = 0; k < bc.n; ++k) {
    if (!(fn(k) > 0)) continue;
    const int a = static_cast<int>(gid(ci(k))), b = static_cast<int>(gid(cj(k)));
    ContactRecord c = record(a, dom.min_image(s.x[b] - s.x[a]), load(fc, k), fn(k));
    c.b = b;
    const Real overlap = s.radius[a] + s.radius[b] - norm(c.branch);
    c.point = s.x[c.a] + (s.radius[c.a] - overlap / 2) * c.normal;
    s.contacts.push_back(c);
  }

  const ContactList& wc = sim.wall_contacts();
  auto wi = Kokkos::create_mirror_view_and_copy(HostSpace(), wc.i);
  auto wj = Kokkos::create_mirror_view_and_copy(HostSpace(), wc.j);
  auto wf = Kokkos::create_mirror_view_and_copy(HostSpace(), wc.fc);
  auto wn = Kokkos::create_mirror_view_and_copy(HostSpace(), wc.fn);
  const WallSet& walls = sim.walls();
  auto kind = Kokkos::create_mirror_view_and_copy(HostSpace(), walls.kind);
  auto wp = Kokkos::create_mirror_view_and_copy(HostSpace(), walls.point);
  auto wnorm = Kokkos::create_mirror_view_and_copy(HostSpace(), walls.normal);
  auto wrad = Kokkos::create_mirror_view_and_copy(HostSpace(), walls.radius);
  const FacetMesh& mesh = sim.mesh();
  auto nx = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.node_x);
  auto tri = Kokkos::create_mirror_view_and_copy(HostSpace(), mesh.tri);
  for (int k = 0; k < wc.n; ++k) {
    if (!(wn(k) > 0)) continue;
    const int a = static_cast<int>(gid(wi(k)));
    const Vec3& x = s.x[a];
    const int obj = wj(k);
    Vec3 cp;
    if (obj < walls.n) {
      if (!wall_closest_point(kind(obj), load(wp, obj), load(wnorm, obj), wrad(obj), x, cp)) continue;
    } else {
      const int t = obj - walls.n;
      cp = closest_on_triangle(x, load(nx, tri(t, 0)), load(nx, tri(t, 1)), load(nx, tri(t, 2))).cp;
    }
    if (!(norm(cp - x) > 0)) continue;
    ContactRecord c = record(a, cp - x, load(wf, k), wn(k));
    c.boundary = obj < walls.n ? Boundary::kPlaten : Boundary::kMembrane;
    c.point = cp;
    s.contacts.push_back(c);
  }
  return s;
}

io::ContactTable contact_table(const ContactSet& s) {
  io::ContactTable t;
  for (const ContactRecord& c : s.contacts) {
    t.a.push_back(c.a);
    t.b.push_back(c.b);
    t.boundary.push_back(static_cast<int>(c.boundary));
    t.fn.push_back(c.fn);
    for (int d = 0; d < 3; ++d) {
      t.normal.push_back(c.normal[d]);
      t.point.push_back(c.point[d]);
      t.branch.push_back(c.branch[d]);
      t.ft.push_back(c.ft[d]);
    }
  }
  return t;
}

ContactSet contact_set(const io::SnapshotFile& f, const std::string& path) {
  if (!f.has_contacts)
    throw std::runtime_error(path + ": the snapshot holds no contacts (only the triaxial test's snapshots at A-D "
                                    "carry them, with [micro] enabled)");
  ContactSet s;
  const std::size_t n = f.particles.radius.size();
  s.x.resize(n);
  s.radius.resize(n);
  std::vector<char> seen(n, 0);
  for (std::size_t q = 0; q < n; ++q) {
    // Rows are in gid order (take_snapshot); the gid column says so, and is used as an index: 0 .. n-1, once each.
    const std::size_t g = f.particles.gid.size() == n ? f.particles.gid[q] : q;
    if (g >= n || seen[g])
      throw std::runtime_error(path + ": /gid, row " + std::to_string(q) + ": " + std::to_string(g) +
                               (g >= n ? " (allowed: 0 to " + std::to_string(n - 1) + ")" : " given twice"));
    seen[g] = 1;
    s.x[g] = Vec3(f.particles.x[3 * q], f.particles.x[3 * q + 1], f.particles.x[3 * q + 2]);
    s.radius[g] = f.particles.radius[q];
  }
  const io::ContactTable& t = f.contacts;
  auto v3 = [](const std::vector<double>& v, std::size_t k) { return Vec3(v[3 * k], v[3 * k + 1], v[3 * k + 2]); };
  for (std::size_t k = 0; k < t.a.size(); ++k) {
    ContactRecord c;
    c.a = t.a[k];
    c.b = t.b[k];
    c.boundary = static_cast<Boundary>(t.boundary[k]);  // 0, 1 or 2, with b a ball exactly for 0 (read_snapshot)
    c.fn = t.fn[k];
    c.normal = v3(t.normal, k);
    c.point = v3(t.point, k);
    c.branch = v3(t.branch, k);
    c.ft = v3(t.ft, k);
    s.contacts.push_back(c);
  }
  return s;
}

}  // namespace dem
