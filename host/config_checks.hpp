#pragma once
/// Checks of the config reader (host/config_checks.cpp), internal to config.cpp.
#include <string>

namespace dem {

/// MemAvailable of /proc/meminfo (bytes), 0 when unknown.
double available_memory();

/// Refuses (ConfigError naming path, line and column) a byte outside ASCII anywhere but in a string or a
/// comment: the toml++ of Debian 12 (3.3.0) reaches undefined behaviour on many such characters.
void check_ascii_outside_strings(const std::string& text, const std::string& path);

}  // namespace dem
