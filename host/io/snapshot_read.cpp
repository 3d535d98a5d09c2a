/// Reading a snapshot back (host/io/io_hdf5.hpp): for `triaxdem micro` and the tests, every array checked.
#include <cmath>
#include <string>
#include <vector>

#include "host/io/h5_file.hpp"
#include "host/io/io_hdf5.hpp"

namespace dem::io {

using namespace h5;

namespace {
void check_finite(const std::string& path, const std::string& name, const std::vector<double>& v,
                  bool positive = false) {
  for (std::size_t k = 0; k < v.size(); ++k)
    if (!std::isfinite(v[k]) || (positive && !(v[k] > 0)))
      throw std::runtime_error(path + ": " + name + ", value " + std::to_string(k) + ": " + std::to_string(v[k]) +
                               (positive ? " (allowed: a finite positive number)" : " (allowed: a finite number)"));
}
}  // namespace

SnapshotFile read_snapshot(const std::string& path) {
  const H5Reader f(path);
  SnapshotFile out;
  out.particles.x = f.read<double>("/x", H5T_NATIVE_DOUBLE, 3);
  out.particles.radius = f.read<double>("/radius", H5T_NATIVE_DOUBLE, 1);
  out.particles.gid = f.read<std::uint32_t>("/gid", H5T_NATIVE_UINT32, 1);
  out.particles.label = f.string_attribute("/", "label");
  const std::size_t balls = out.particles.radius.size();
  if (out.particles.x.size() != 3 * balls)
    throw std::runtime_error(path + ": /x and /radius disagree on the number of balls");
  if (out.particles.gid.size() != balls)
    throw std::runtime_error(path + ": /gid has " + std::to_string(out.particles.gid.size()) + " rows (allowed: " +
                             std::to_string(balls) + ", one per ball)");
  check_finite(path, "/x", out.particles.x);
  check_finite(path, "/radius", out.particles.radius, true);
  out.has_surface = f.exists("/surface");
  if (out.has_surface) {
    out.surface.nodes = f.read<double>("/surface/nodes", H5T_NATIVE_DOUBLE, 3);
    out.surface.triangles = f.read<int>("/surface/triangles", H5T_NATIVE_INT, 3);
    check_finite(path, "/surface/nodes", out.surface.nodes);
    const std::size_t nodes = out.surface.nodes.size() / 3;
    for (std::size_t k = 0; k < out.surface.triangles.size(); ++k)
      if (out.surface.triangles[k] < 0 || static_cast<std::size_t>(out.surface.triangles[k]) >= nodes)
        throw std::runtime_error(path + ": /surface/triangles, row " + std::to_string(k / 3) + ": node " +
                                 std::to_string(out.surface.triangles[k]) + " (allowed: 0 to " +
                                 std::to_string(static_cast<long>(nodes) - 1) + ")");
  }
  out.has_contacts = f.exists("/contacts");
  if (out.has_contacts) {
    ContactTable& c = out.contacts;
    c.a = f.read<int>("/contacts/a", H5T_NATIVE_INT, 1);
    c.b = f.read<int>("/contacts/b", H5T_NATIVE_INT, 1);
    c.boundary = f.read<int>("/contacts/boundary", H5T_NATIVE_INT, 1);
    c.fn = f.read<double>("/contacts/fn", H5T_NATIVE_DOUBLE, 1);
    c.normal = f.read<double>("/contacts/normal", H5T_NATIVE_DOUBLE, 3);
    c.point = f.read<double>("/contacts/point", H5T_NATIVE_DOUBLE, 3);
    c.branch = f.read<double>("/contacts/branch", H5T_NATIVE_DOUBLE, 3);
    c.ft = f.read<double>("/contacts/ft", H5T_NATIVE_DOUBLE, 3);
    const std::size_t n = c.a.size();
    if (c.b.size() != n || c.boundary.size() != n || c.fn.size() != n || c.normal.size() != 3 * n ||
        c.point.size() != 3 * n || c.branch.size() != 3 * n || c.ft.size() != 3 * n)
      throw std::runtime_error(path + ": /contacts datasets of unequal length (" + std::to_string(n) +
                               " rows of a)");
    for (std::size_t k = 0; k < n; ++k) {
      if (c.a[k] < 0 || std::size_t(c.a[k]) >= balls || c.b[k] < -1 || (c.b[k] >= 0 && std::size_t(c.b[k]) >= balls))
        throw std::runtime_error(path + ": /contacts, row " + std::to_string(k) + ": a ball that is not in the file "
                                 "(allowed: 0 to " + std::to_string(static_cast<long>(balls) - 1) + ", b also -1)");
      // boundary 0: between two balls (b a ball); 1 platen, 2 membrane (b = -1).
      if (c.boundary[k] < 0 || c.boundary[k] > 2 || (c.boundary[k] == 0) != (c.b[k] >= 0))
        throw std::runtime_error(path + ": /contacts, row " + std::to_string(k) + ": boundary " +
                                 std::to_string(c.boundary[k]) + " with b = " + std::to_string(c.b[k]) +
                                 " (allowed: 0 with a ball b, 1 or 2 with b = -1)");
    }
    for (const auto& [name, v] : {std::make_pair("/contacts/fn", &c.fn), std::make_pair("/contacts/normal", &c.normal),
                                  std::make_pair("/contacts/point", &c.point),
                                  std::make_pair("/contacts/branch", &c.branch), std::make_pair("/contacts/ft", &c.ft)})
      check_finite(path, name, *v);
  }
  return out;
}

}  // namespace dem::io
