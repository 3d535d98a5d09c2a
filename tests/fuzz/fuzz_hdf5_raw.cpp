/// The HDF5 readers on raw bytes (seeds: checkpoints and snapshots of a short run, a snapshot with contacts,
/// measured data in HDF5 form), the first byte picking the reader: checkpoint (with the resume's state checks),
/// snapshot (with what `triaxdem micro` does with it) or measured data. This fuzzes libhdf5's own parser as much as
/// triaxdem: Debian's libhdf5 1.10.8 has memory errors on malformed object headers (found in H5O__attr_exists,
/// tests/fuzz/regressions/raw), which triaxdem cannot mend, so this harness is for manual runs
/// (tests/fuzz/run_fuzz.sh SECONDS fuzz_hdf5_raw), not the CI gate; the gate fuzzes the same readers through
/// well-formed files (fuzz_checkpoint_values, fuzz_snapshot_values).
#include "fuzz_file.hpp"
#include "host/engine/checkpoint.hpp"
#include "host/data/measured.hpp"
#include "host/engine/micro.hpp"
#include "host/triax/micro_report.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  switch (data[0] % 3) {
    case 0:
      return dem::fuzz::read_bytes(data + 1, size - 1, ".h5", [](const std::string& path) {
        const dem::Checkpoint c = dem::read_checkpoint(path);
        dem::check_state(c.sim, c.sim.wall_point.size() / 3, 1024, 16);
      });
    case 1:
      return dem::fuzz::read_bytes(data + 1, size - 1, ".h5", [](const std::string& path) {
        const dem::io::SnapshotFile f = dem::io::read_snapshot(path);
        if (f.has_surface) dem::surface_volume(f.surface);
        if (f.has_contacts) dem::micro_row(dem::contact_set(f, path), 1e-6);
      });
    default:
      return dem::fuzz::read_bytes(data + 1, size - 1, ".h5", [](const std::string& p) { dem::load_measured(p); });
  }
}
