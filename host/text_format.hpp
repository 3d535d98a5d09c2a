#pragma once
/// One number through a printf format, as a string: the cells of the reports' tables.
#include <cstdio>
#include <string>

namespace dem {

inline std::string fmt(const char* format, double v) {
  char b[96];
  std::snprintf(b, sizeof b, format, v);
  return b;
}

}  // namespace dem
