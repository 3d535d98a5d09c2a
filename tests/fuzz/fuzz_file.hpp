#pragma once
/// What every file-reader harness shares: the fuzzer's bytes go through one file of this process (the readers
/// read files), and the reader must return or refuse the file with std::runtime_error (DataError and ConfigError
/// are kinds of it). Anything else (a crash, a sanitizer report, std::bad_alloc, a logic_error) is a finding.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <string>

namespace dem::fuzz {

template <class Read>
int read_bytes(const std::uint8_t* data, std::size_t size, const char* suffix, Read read) {
  static const std::string path = "/tmp/triaxdem_fuzz_" + std::to_string(::getpid()) + suffix;
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return 0;
  std::fwrite(data, 1, size, f);
  std::fclose(f);
  try {
    read(path);
  } catch (const std::runtime_error&) {
  }
  return 0;
}

}  // namespace dem::fuzz
