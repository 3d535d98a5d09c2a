/// The contacts of a state, gathered for the micromechanics (host/engine/micro.hpp): from a running simulation or from
/// a saved snapshot, and back into a snapshot's contact table.
#include <algorithm>
#include <array>
#include <stdexcept>
#include <string>

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

/// The first n values of a one-dimensional device View, in a host vector of their own.
template <class V>
std::vector<typename V::non_const_value_type> host_values(const V& v, int n) {
  const auto h = Kokkos::create_mirror_view_and_copy(HostSpace(), Kokkos::subview(v, std::make_pair(0, n)));
  return std::vector<typename V::non_const_value_type>(h.data(), h.data() + n);
}
/// The first n rows of a View of rows (3-vectors, the facets' node triples), each read by `row`, likewise.
template <class V, class Row>
auto host_rows(const V& v, int n, Row row) {
  const auto h = Kokkos::create_mirror_view_and_copy(HostSpace(), v);
  std::vector<decltype(row(h, 0))> out(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) out[k] = row(h, k);
  return out;
}
std::vector<Vec3> host_rows(const Vec3View& v, int n) {
  return host_rows(v, n, [](const auto& h, int k) { return load(h, k); });
}
ContactCopy::List host_list(const ContactList& l) {
  return {host_values(l.i, l.n), host_values(l.j, l.n), host_rows(l.fc, l.n), host_values(l.fn, l.n)};
}

}  // namespace

ContactCopy copy_contacts(Simulation& sim) {
  const Particles& p = sim.particles();
  ContactCopy c;
  const auto gid = host_values(p.gid, p.n);
  c.gid.assign(gid.begin(), gid.end());
  const std::vector<Vec3> x = host_rows(p.x, p.n);
  const std::vector<Real> rad = host_values(p.radius, p.n);
  c.x.resize(p.n);
  c.radius.resize(p.n);
  for (int i = 0; i < p.n; ++i) {
    c.x[c.gid[i]] = x[i];
    c.radius[c.gid[i]] = rad[i];
  }
  c.balls = host_list(sim.ball_contacts());
  c.walls = host_list(sim.wall_contacts());
  const WallSet& walls = sim.walls();
  c.wall_kind = host_values(walls.kind, walls.n);
  c.wall_point = host_rows(walls.point, walls.n);
  c.wall_normal = host_rows(walls.normal, walls.n);
  c.wall_radius = host_values(walls.radius, walls.n);
  const FacetMesh& mesh = sim.mesh();
  c.node_x = host_rows(mesh.node_x, mesh.nnode);
  c.tri = host_rows(mesh.tri, mesh.ntri,
                    [](const auto& h, int k) { return std::array<int, 3>{h(k, 0), h(k, 1), h(k, 2)}; });
  c.domain = sim.domain();
  return c;
}

ContactSet contact_set(const ContactCopy& c) {
  ContactSet s;
  s.x = c.x;
  s.radius = c.radius;
  const ContactCopy::List& bc = c.balls;
  for (std::size_t k = 0; k < bc.fn.size(); ++k) {
    if (!(bc.fn[k] > 0)) continue;
    const int a = c.gid[bc.i[k]], b = c.gid[bc.j[k]];
    ContactRecord r = record(a, c.domain.min_image(s.x[b] - s.x[a]), bc.fc[k], bc.fn[k]);
    r.b = b;
    const Real overlap = s.radius[a] + s.radius[b] - norm(r.branch);
    r.point = s.x[r.a] + (s.radius[r.a] - overlap / 2) * r.normal;
    s.contacts.push_back(r);
  }
  const ContactCopy::List& wc = c.walls;
  const int nwalls = static_cast<int>(c.wall_kind.size());
  for (std::size_t k = 0; k < wc.fn.size(); ++k) {
    if (!(wc.fn[k] > 0)) continue;
    const int a = c.gid[wc.i[k]];
    const Vec3& x = s.x[a];
    const int obj = wc.j[k];
    Vec3 cp;
    if (obj < nwalls) {
      if (!wall_closest_point(c.wall_kind[obj], c.wall_point[obj], c.wall_normal[obj], c.wall_radius[obj], x, cp))
        continue;
    } else {
      const std::array<int, 3>& t = c.tri[obj - nwalls];
      cp = closest_on_triangle(x, c.node_x[t[0]], c.node_x[t[1]], c.node_x[t[2]]).cp;
    }
    if (!(norm(cp - x) > 0)) continue;
    ContactRecord r = record(a, cp - x, wc.fc[k], wc.fn[k]);
    r.boundary = obj < nwalls ? Boundary::kPlaten : Boundary::kMembrane;
    r.point = cp;
    s.contacts.push_back(r);
  }
  return s;
}

ContactSet contact_set(Simulation& sim) { return contact_set(copy_contacts(sim)); }

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
