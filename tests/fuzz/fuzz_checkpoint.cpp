/// The checkpoint reader on arbitrary bytes (seeds: checkpoints of a short run): the file is read, and its state
/// checked as a resume checks it, against the walls it declares and generous material and facet counts.
#include "fuzz_file.hpp"
#include "host/checkpoint.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return dem::fuzz::read_bytes(data, size, ".h5", [](const std::string& path) {
    const dem::Checkpoint c = dem::read_checkpoint(path);
    dem::check_state(c.sim, c.sim.wall_point.size() / 3, 1024, 16);
  });
}
