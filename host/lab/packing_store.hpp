#pragma once
/// Packed cell specimens kept on disk and read back instead of packed again (Config::packing_store): a packing is
/// decided by the config, the cell's size and boundary, the preparation friction and the seed, so every stage of a
/// job (the state match's packings, the scatter specimens, the cell's bias check) and every later job on the same
/// base reads a packing once made. The same bytes carry a specimen from a forked child to its parent.
#include <array>
#include <string>
#include <vector>

#include "host/config/config.hpp"
#include "host/engine/builder.hpp"

namespace dem {

/// A specimen: its balls packed and prepared in their cell (m), and the void ratio they reached.
struct PackedCell {
  std::vector<BallSpec> balls;
  std::array<Real, 3> cell{};
  Real void_ratio = 0;
};

/// The store's file of the specimen `cfg` packs with its [run] seed: named by a hash of the program's version, the
/// config's fingerprint and what a job changes in code (the cell's balls, size and boundary, the preparation
/// friction, the ball law, the seed). "" where cfg names no store, or has no fingerprint (built in code: its
/// settings are not all in the hash).
std::string packing_path(const Config& cfg);

/// The specimen as bytes: its ball count, balls, cell and void ratio, then their checksum.
std::string packed_bytes(const PackedCell& s);

/// Reads packed_bytes from fd into s; false where they are cut short, the count is not `balls` or the checksum
/// differs (a damaged file is packed again, never used).
bool get_packed(int fd, PackedCell& s, std::size_t balls);

/// The specimen of `cfg` from its store file; false where there is none or it is damaged.
bool read_packing(const Config& cfg, PackedCell& s);

/// Keeps the specimen of `cfg` in its store file (nothing where cfg names no store).
void write_packing(const Config& cfg, const PackedCell& s);

}  // namespace dem
