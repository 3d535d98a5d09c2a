#pragma once
/// One number through a printf format, as a string: the cells of the reports' tables.
#include <cstdio>
#include <string>
#include <type_traits>

namespace dem {

inline std::string fmt(const char* format, double v) {
  char b[96];
  std::snprintf(b, sizeof b, format, v);
  return b;
}
/// An integer would reach a %d or %ld format as a double (undefined; a run count printed as 0 or 6): refused here,
/// so that counts are written with std::to_string and a number meant as a double is converted where it is passed.
template <class T, std::enable_if_t<std::is_integral_v<T>, int> = 0>
std::string fmt(const char* format, T v) = delete;

}  // namespace dem
