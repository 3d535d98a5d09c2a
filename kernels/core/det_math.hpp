#pragma once
/// Functions beyond IEEE's exactly rounded five (+ - * / sqrt) written with those alone, so that a CPU and a GPU
/// give the same bits: CUDA's exp and glibc's are each within an ulp of the true value and differ in the last bit,
/// which a packing's chaotic path turned into a 5e-4 difference of a peak (Reference.PeriodicCell's wear row on an
/// H100, docs/performance.md). The build fuses no multiply-add on either (-ffp-contract=off, nvcc --fmad=false).
#include <cstdint>
#include <cstring>

#include <Kokkos_Core.hpp>

namespace dem::kc {

/// 2^k for k in [-1022, 1023], from its exponent bits.
KOKKOS_INLINE_FUNCTION double pow2(int k) {
  const std::uint64_t bits = static_cast<std::uint64_t>(k + 1023) << 52;
  double v;
  std::memcpy(&v, &bits, sizeof v);
  return v;
}

/// e^x within 2 ulp of the true value (tests/test_contact_law.cpp checks it against std::exp), the same bits on
/// every backend. Cody-Waite reduction x = n ln2 + r with ln2 split so that n ln2_hi is exact for |n| < 2^11,
/// |r| <= ln2 / 2, then Taylor to degree 13 (truncation below 4e-18 of the result) and 2^n put in by its bits.
KOKKOS_INLINE_FUNCTION double exp(double x) {
  if (!(x == x)) return x;                 // NaN
  if (x < -745.1332191019412) return 0.0;  // below half the smallest subnormal
  if (x > 710.0) x = 710.0;                 // e^710 already overflows to infinity below
  constexpr double kInvLn2 = 1.4426950408889634074;
  constexpr double kLn2Hi = 6.93147180369123816490e-01;  // the high 32 bits of ln 2 (fdlibm's split)
  constexpr double kLn2Lo = 1.90821492927058770002e-10;
  // n = round(x / ln2), by floor of the shifted value: exact, and the same on every backend.
  const double t = x * kInvLn2 + 0.5;
  double n = static_cast<double>(static_cast<std::int64_t>(t));
  if (n > t) n -= 1;
  const double r = (x - n * kLn2Hi) - n * kLn2Lo;
  double p = 1.0 / 6227020800.0;  // 1/13!
  p = p * r + 1.0 / 479001600.0;
  p = p * r + 1.0 / 39916800.0;
  p = p * r + 1.0 / 3628800.0;
  p = p * r + 1.0 / 362880.0;
  p = p * r + 1.0 / 40320.0;
  p = p * r + 1.0 / 5040.0;
  p = p * r + 1.0 / 720.0;
  p = p * r + 1.0 / 120.0;
  p = p * r + 1.0 / 24.0;
  p = p * r + 1.0 / 6.0;
  p = p * r + 0.5;
  p = p * r + 1.0;
  p = p * r + 1.0;
  // p 2^n, the factor split where 2^n is no normal number: above, the product overflows to infinity; below, the
  // second factor rounds it into the subnormals.
  const int k = static_cast<int>(n);
  if (k >= -1022) return k > 1023 ? p * pow2(1023) * pow2(k - 1023) : p * pow2(k);
  return p * pow2(k + 1000) * pow2(-1000);
}

}  // namespace dem::kc
