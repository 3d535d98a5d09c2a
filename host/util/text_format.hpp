#pragma once
/// Text in and out of tables: one number through a printf format (the cells of the reports' tables), and the
/// fields of a comma-separated line (every CSV and name list triaxdem reads).
#include <cstdio>
#include <string>
#include <type_traits>
#include <vector>

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

/// The fields of a line separated by `sep`, each as written: "a,,b," gives "a", "", "b", "" (an empty last field
/// after a trailing separator, which a row's cell count must see), and "" gives one empty field.
std::vector<std::string> split_fields(const std::string& line, char sep = ',');
/// s without its leading and trailing blanks (spaces, tabs, a carriage return).
std::string trim(const std::string& s);
/// The fields of a comma-separated line, each trimmed: a CSV row's cells.
std::vector<std::string> split_cells(const std::string& line);

}  // namespace dem
