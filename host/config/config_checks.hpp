#pragma once
/// Checks of the config reader (host/config/config_checks.cpp), internal to config.cpp.
#include <string>

namespace dem {

/// MemAvailable of /proc/meminfo (bytes), 0 when unknown.
double available_memory();

/// Refuses (ConfigError naming path, line and column) a byte outside ASCII anywhere but in a string or a
/// comment: the toml++ of Debian 12 (3.3.0) reaches undefined behaviour on many such characters.
void check_ascii_outside_strings(const std::string& text, const std::string& path);

/// Refuses (ConfigError naming path, table and key) a record interval `every` that leaves fewer than kMinRecords
/// records to the end strain `end` (fractions): the curve is summarised by a moving mean over +-0.25% strain
/// (host/data/measured.hpp), and a few rows give a "peak" at whichever of them is highest.
void check_records(const std::string& path, const char* table, const char* key, double every, const char* end_key,
                   double end);

}  // namespace dem
