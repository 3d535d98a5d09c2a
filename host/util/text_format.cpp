#include "host/util/text_format.hpp"

namespace dem {

std::vector<std::string> split_fields(const std::string& line, char sep) {
  std::vector<std::string> out;
  std::size_t at = 0;
  for (std::size_t next; (next = line.find(sep, at)) != std::string::npos; at = next + 1)
    out.push_back(line.substr(at, next - at));
  out.push_back(line.substr(at));
  return out;
}

std::vector<std::string> split_cells(const std::string& line) {
  std::vector<std::string> out = split_fields(line);
  for (std::string& c : out) c = trim(c);
  return out;
}

std::string trim(const std::string& s) {
  const auto a = s.find_first_not_of(" \t\r");
  if (a == std::string::npos) return "";
  return s.substr(a, s.find_last_not_of(" \t\r") - a + 1);
}

}  // namespace dem
