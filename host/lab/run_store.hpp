#pragma once
/// The run store of a calibration (PeriodicLab::set_run_store): files named by a hash of what decides them, read
/// back instead of recomputed. Shared by the lab's runs and the state match's packings.
#include <cstdint>
#include <functional>
#include <string>

#include "host/config/config.hpp"
#include "host/data/measured.hpp"

namespace dem {

/// The hash every stored file's name starts from: the program's version and the config's fingerprint; the caller
/// hashes in what else decides the file.
std::uint64_t store_hash(const Config& cfg);

/// Reads a stored file through `read` (given its descriptor); false where there is none, where it does not match the
/// checksum write_stored sealed it with (a note on stderr says it is computed again), or where `read` does not take
/// exactly the sealed bytes.
bool read_stored(const std::string& path, const std::function<bool(int fd)>& read);

/// Writes `bytes` and their FNV-1a checksum to `path` atomically (io::write_text_atomic), making its folder at the
/// first file: a killed calibration leaves whole files only, and a file damaged later is never read. Throws std::runtime_error naming the path.
void write_stored(const std::string& path, const std::string& bytes);

/// A run's curves through a child's pipe: its row count, void ratio, eps_a, q and eps_v (a run that blew up: every
/// quantity missing). The receiver summarises them as the sender's test was summarised (set its sigma3 first);
/// false where the bytes are cut short.
void send_curves(int fd, const TriaxialTest& t);
bool receive_curves(int fd, TriaxialTest& t);

}  // namespace dem
