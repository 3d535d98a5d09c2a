/// The contacts of a state, gathered for the micromechanics (host/engine/micro.hpp): from a running simulation or from
/// a saved snapshot, and back into a snapshot's contact table.
#include <algorithm>
#include <array>
#include <stdexcept>
#include <string>

#include "host/io/io_hdf5.hpp"
#include "host/engine/micro.hpp"
#include "host/engine/simulation.hpp"
#include "host/engine/state_copy.hpp"

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

ContactSet contact_set(const ContactCopy& c) {
  if (!c.contacts) throw std::logic_error("contact_set: a copy of the state taken without its contacts (copy_state)");
  ContactSet s;
  s.x = centres_by_gid(c);
  s.radius.resize(static_cast<std::size_t>(c.n));
  for (int i = 0; i < c.n; ++i) s.radius[c.gid(i)] = c.radius(i);
  const ContactCopy::List& bc = c.balls;
  for (int k = 0; k < bc.n; ++k) {
    if (!(bc.fn(k) > 0)) continue;
    const int a = static_cast<int>(c.gid(bc.i(k))), b = static_cast<int>(c.gid(bc.j(k)));
    ContactRecord r = record(a, c.domain.min_image(s.x[b] - s.x[a]), load(bc.fc, k), bc.fn(k));
    r.b = b;
    const Real overlap = s.radius[a] + s.radius[b] - norm(r.branch);
    r.point = s.x[r.a] + (s.radius[r.a] - overlap / 2) * r.normal;
    s.contacts.push_back(r);
  }
  const ContactCopy::List& wc = c.walls;
  const int nwalls = c.nwalls;
  for (int k = 0; k < wc.n; ++k) {
    if (!(wc.fn(k) > 0)) continue;
    const int a = static_cast<int>(c.gid(wc.i(k)));
    const Vec3& x = s.x[a];
    const int obj = wc.j(k);
    Vec3 cp;
    if (obj < nwalls) {
      if (!wall_closest_point(c.wall_kind(obj), load(c.wall_point, obj), load(c.wall_normal, obj), c.wall_radius(obj),
                              x, cp))
        continue;
    } else {
      const int t = obj - nwalls;
      cp = closest_on_triangle(x, load(c.node_x, c.tri(t, 0)), load(c.node_x, c.tri(t, 1)), load(c.node_x, c.tri(t, 2)))
               .cp;
    }
    if (!(norm(cp - x) > 0)) continue;
    ContactRecord r = record(a, cp - x, load(wc.fc, k), wc.fn(k));
    r.boundary = obj < nwalls ? Boundary::kPlaten : Boundary::kMembrane;
    r.point = cp;
    s.contacts.push_back(r);
  }
  return s;
}

ContactSet contact_set(Simulation& sim) {
  ContactCopy c;
  copy_state(sim, true, c);
  return contact_set(c);
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
