/// The snapshot reader and what `triaxdem micro` does with a snapshot (seeds: snapshots of a short run and one
/// with contacts and a membrane surface): read, the contact set built, the micro measures and the surface's
/// enclosed volume taken.
#include "fuzz_file.hpp"
#include "host/micro.hpp"
#include "host/micro_report.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return dem::fuzz::read_bytes(data, size, ".h5", [](const std::string& path) {
    const dem::io::SnapshotFile f = dem::io::read_snapshot(path);
    if (f.has_surface) dem::surface_volume(f.surface);
    if (f.has_contacts) dem::micro_row(dem::contact_set(f, path), 1e-6);
  });
}
