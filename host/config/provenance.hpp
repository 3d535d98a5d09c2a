#pragma once
/// What a result came from, written beside it (summary.csv) and printed by --version: the program's version and
/// commit, the Kokkos backend that ran it, and the config (path, settings hash, seed).
#include <string>

#include "host/config/config.hpp"

namespace dem {

struct Provenance {
  std::string version;      ///< "0.1.0+abc1234" (the commit; "-dirty" when the tree had changes)
  std::string backend;      ///< "OpenMP x2", "Cuda", ...
  std::string config;       ///< the config's path as given
  std::string config_hash;  ///< 16 hex digits of the config's settings (Config::fingerprint), not its spelling
  long seed = 0;            ///< [run] seed
};

/// The program's version and commit, as in Provenance::version.
std::string program_version();
/// One line for --version: the version, the commit and the Kokkos build (version, backend).
std::string version_line();
/// The provenance of a run of `cfg` on this build; the backend needs Kokkos initialised.
Provenance provenance_of(const Config& cfg);

}  // namespace dem
