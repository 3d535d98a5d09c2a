/// The config parser on arbitrary bytes: a valid config or a ConfigError, nothing else.
#include <cstddef>
#include <cstdint>
#include <string>

#include "host/config/config.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    dem::parse_config(std::string(reinterpret_cast<const char*>(data), size), "<fuzz>.toml");
  } catch (const dem::ConfigError&) {
  }
  return 0;
}
