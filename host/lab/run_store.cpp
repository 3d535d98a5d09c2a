#include "host/lab/run_store.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>
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

namespace {
/// The whole file at `fd`, "" where it cannot be read.
std::string all_bytes(int fd) {
  std::string out;
  char chunk[1 << 16];
  for (ssize_t n; (n = ::read(fd, chunk, sizeof chunk)) != 0;) {
    if (n < 0) return "";
    out.append(chunk, static_cast<std::size_t>(n));
  }
  return out;
}
}  // namespace

bool read_stored(const std::string& path, const std::function<bool(int fd)>& read) {
  if (path.empty()) return false;
  const int fd = ::open(path.c_str(), O_RDONLY);
  if (fd < 0) return false;
  // The seal first, so that `read` never sees a file changed since it was written (a byte flipped on the disk, a file
  // cut short that still parses, an edit); then exactly the sealed bytes, no more and no fewer.
  const std::string bytes = all_bytes(fd);
  const std::size_t body = bytes.size() >= sizeof(std::uint64_t) ? bytes.size() - sizeof(std::uint64_t) : 0;
  std::uint64_t seal = 0;
  if (body > 0) std::memcpy(&seal, bytes.data() + body, sizeof seal);
  bool ok = body > 0 && seal == fnv1a(bytes.data(), body) && ::lseek(fd, 0, SEEK_SET) == 0 && read(fd) &&
            ::lseek(fd, 0, SEEK_CUR) == static_cast<off_t>(body);
  ::close(fd);
  if (!ok)
    std::fprintf(stderr, "note: the stored file %s does not match its checksum (damaged, cut short or written by "
                 "another version): computed again\n", path.c_str());
  return ok;
}

void write_stored(const std::string& path, const std::string& bytes) {
  if (!ranks::leader()) return;
  std::filesystem::create_directories(std::filesystem::path(path).parent_path());
  const std::uint64_t seal = fnv1a(bytes.data(), bytes.size());
  io::write_text_atomic(path, bytes + std::string(reinterpret_cast<const char*>(&seal), sizeof seal));
}

}  // namespace dem
