#pragma once
/// The simple cubic lattice of the walled cell's tests (its size under load is known in closed form), for the test
/// files of the engine's layer and above (tests/test_util.hpp stays below it).
#include <vector>

#include "host/engine/builder.hpp"

namespace dem::test {

/// A simple cubic lattice of n^3 glass balls of radius r, their centres 2 r `gap` apart from (r gap, r gap, r gap):
/// gap 1 touching, above 1 apart, in a cube of side 2 n r gap.
inline std::vector<BallSpec> cubic_lattice(int n, double r, double gap) {
  std::vector<BallSpec> balls;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k) {
        BallSpec b;
        b.radius = r;
        b.density = 2500;
        b.x = gap * Vec3((2 * i + 1) * r, (2 * j + 1) * r, (2 * k + 1) * r);
        balls.push_back(b);
      }
  return balls;
}

}  // namespace dem::test
