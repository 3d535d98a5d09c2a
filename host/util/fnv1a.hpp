#pragma once
// FNV-1a, the 64-bit hash of the config fingerprint and the checkpoint checksum: not cryptographic, it finds
// edits and damage, not forgery.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

namespace dem {

inline constexpr std::uint64_t kFnv1aOffset = 14695981039346656037ull;

/// Continues hash h over n bytes.
inline std::uint64_t fnv1a(const void* data, std::size_t n, std::uint64_t h = kFnv1aOffset) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t k = 0; k < n; ++k) h = (h ^ p[k]) * 1099511628211ull;
  return h;
}

/// Sixteen hexadecimal digits, as files store the hash.
inline std::string hex16(std::uint64_t h) {
  char b[17];
  std::snprintf(b, sizeof b, "%016llx", static_cast<unsigned long long>(h));
  return b;
}

}  // namespace dem
