#include "host/engine/membrane_mesh.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "host/engine/builder.hpp"

namespace dem {

MembraneMesh make_cylinder_membrane(int n_around, int n_segments, Real radius, Real z0, Real height) {
  auto bad = [](const std::string& what) { throw std::invalid_argument("make_cylinder_membrane: " + what); };
  // Fewer than 8 sides is no cylinder: the inscribed octagon already has 10 % less area than its circle.
  if (n_around < 8) bad("n_around must be >= 8 (got " + std::to_string(n_around) + ")");
  if (n_segments < 1) bad("n_segments must be >= 1 (got " + std::to_string(n_segments) + ")");
  if (!(radius > 0) || !std::isfinite(radius)) bad("radius must be finite and > 0 m (got " + std::to_string(radius) + ")");
  if (!(height > 0) || !std::isfinite(height)) bad("height must be finite and > 0 m (got " + std::to_string(height) + ")");
  if (!std::isfinite(z0)) bad("z0 must be finite");
  // Corner indices 3 f + q must fit in an int.
  if (static_cast<long long>(n_around) * n_segments > std::numeric_limits<int>::max() / 6)
    bad("n_around * n_segments must be <= " + std::to_string(std::numeric_limits<int>::max() / 6));

  MembraneMesh m;
  m.n_around = n_around;
  m.n_segments = n_segments;
  const int nr = n_segments + 1;
  m.nodes.reserve(3 * static_cast<std::size_t>(n_around) * nr);
  for (int r = 0; r < nr; ++r) {
    // The top ring gets z0 + height exactly, so it lies on the platen plane.
    const Real z = r == n_segments ? z0 + height : z0 + height * r / n_segments;
    for (int k = 0; k < n_around; ++k) {
      const Real th = 2 * M_PI * k / n_around;
      m.nodes.push_back(radius * std::cos(th));
      m.nodes.push_back(radius * std::sin(th));
      m.nodes.push_back(z);
    }
  }
  // Quad (a, b, c, d) = ((r, k), (r, k+1), (r+1, k+1), (r+1, k)) is counter-clockwise seen from outside
  // (e_theta x e_z = e_r). The diagonal alternates between bands: with one direction everywhere the
  // diagonals, the stiffest lines of a CST mesh, would all wind as helices of one hand, and a
  // non-uniform deformation such as bulging would twist the membrane against its tied end rings.
  // Alternating makes neighbouring bands mirror images, so the handedness cancels; every interior node
  // keeps 6 neighbours. Axisymmetric states are unaffected: each quad's two rings are parallel chords,
  // so the quad is planar and the volume does not depend on the diagonal.
  m.tris.reserve(6 * static_cast<std::size_t>(n_around) * n_segments);
  for (int r = 0; r < n_segments; ++r) {
    for (int k = 0; k < n_around; ++k) {
      const int k1 = (k + 1) % n_around;
      const int a = r * n_around + k, b = r * n_around + k1, c = (r + 1) * n_around + k1, d = (r + 1) * n_around + k;
      const int t[6] = {a, b, c, a, c, d};      // diagonal a-c
      const int u[6] = {a, b, d, b, c, d};      // diagonal b-d
      const int* s = r % 2 == 0 ? t : u;
      m.tris.insert(m.tris.end(), s, s + 6);
    }
  }
  for (int k = 0; k < n_around; ++k) {
    m.bottom.push_back(k);
    m.top.push_back(n_segments * n_around + k);
  }
  return m;
}

Membrane make_membrane(const MembraneMesh& mesh, const MembraneMaterial& mat, int material) {
  return build_membrane(make_mesh(mesh.nodes, mesh.tris, material), mesh.bottom, mesh.top, mat);
}

}  // namespace dem
