#pragma once
/// The deterministic reductions' tree (kernels/core/reduce.hpp) written out plainly on the host, from its description
/// alone: what a device reduction must give to the bit.
#include <vector>

#include "kernels/core/reduce.hpp"

namespace dem::test {

inline double tree_sum(std::vector<double> level) {
  constexpr int B = kReduceBlock;
  while (true) {
    const std::size_t nblock = (level.size() + B - 1) / B;
    std::vector<double> next(nblock);
    for (std::size_t b = 0; b < nblock; ++b) {
      double s[B];
      for (int k = 0; k < B; ++k) s[k] = b * B + k < level.size() ? level[b * B + k] : 0.0;
      for (int h = B / 2; h >= 1; h /= 2)
        for (int k = 0; k < h; ++k) s[k] += s[k + h];
      next[b] = s[0];
    }
    if (nblock <= 1) return nblock == 1 ? next[0] : 0.0;
    level.swap(next);
  }
}

}  // namespace dem::test
