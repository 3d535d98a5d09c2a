/// The measured-data parser (CSV) on arbitrary bytes: measured data, summarised, or a DataError, nothing else.
/// The parser reads files, so each input goes through one file of this process.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

#include "host/data/measured.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string path = "/tmp/triaxdem_fuzz_measured_" + std::to_string(::getpid()) + ".csv";
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return 0;
  std::fwrite(data, 1, size, f);
  std::fclose(f);
  try {
    dem::load_measured(path);
  } catch (const dem::DataError&) {
  }
  return 0;
}
