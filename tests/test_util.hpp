#pragma once
/// Small helpers shared by the test files.
#include "kernels/contact_law.hpp"

namespace dem::test {

constexpr double kPi = 3.14159265358979323846;

/// Contact parameters in one line: E* (Pa), kn/ks, mu_s, mu_r, normal damping ratio.
inline ContactParams law(double emod, double kratio, double mu_s, double mu_r, double beta_n = 0) {
  ContactParams p;
  p.emod = emod;
  p.kratio = kratio;
  p.mu_s = mu_s;
  p.mu_r = mu_r;
  p.beta_n = beta_n;
  return p;
}

}  // namespace dem::test
