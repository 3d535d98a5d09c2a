#include "host/lab/run_store.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <filesystem>

#include "host/util/fnv1a.hpp"
#include "host/io/io_hdf5.hpp"
#include "host/config/provenance.hpp"
#include "host/util/ranks.hpp"

namespace dem {

std::uint64_t store_hash(const Config& cfg) {
  const std::string version = program_version();
  return fnv1a(cfg.fingerprint.data(), cfg.fingerprint.size(), fnv1a(version.data(), version.size()));
}

bool read_stored(const std::string& path, const std::function<bool(int fd)>& read) {
  if (path.empty()) return false;
  const int fd = ::open(path.c_str(), O_RDONLY);
  if (fd < 0) return false;
  const bool ok = read(fd);
  ::close(fd);
  return ok;
}

void write_stored(const std::string& path, const std::string& bytes) {
  if (!ranks::leader()) return;
  std::filesystem::create_directories(std::filesystem::path(path).parent_path());
  io::write_text_atomic(path, bytes);
}

}  // namespace dem
