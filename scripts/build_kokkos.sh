#!/usr/bin/env bash
# Builds Kokkos 3.4.01 (OpenMP + Serial, C++17) from Debian bookworm's trilinos source package into a
# cached prefix outside the repository (CI runs in a fresh clone, so an in-repo cache would always miss).
# Debian ships Kokkos only inside Trilinos (Serial only, C++14): packages/kokkos alone is unpacked from the
# trilinos orig tarball and built standalone, unpatched. About 20 s on a miss, instant on a hit.
set -euo pipefail
PREFIX="${KOKKOS_PREFIX:-/opt/kokkos-3.4.01-omp}"
CFG_H="$PREFIX/include/KokkosCore_config.h"
if [ -f "$PREFIX/lib/cmake/Kokkos/KokkosConfig.cmake" ] \
   && grep -q '^#define KOKKOS_ENABLE_OPENMP' "$CFG_H" 2>/dev/null \
   && grep -q '^#define KOKKOS_ENABLE_CXX17' "$CFG_H" 2>/dev/null; then
  echo "kokkos: using cached install at $PREFIX"; exit 0
fi
export DEBIAN_FRONTEND=noninteractive
SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO="sudo"
# deb-src entries are off by default in Debian's container images.
if ! apt-cache showsrc trilinos 2>/dev/null | grep -q '^Package: trilinos'; then
  if [ -f /etc/apt/sources.list.d/debian.sources ]; then
    $SUDO sed -i 's/^Types: deb$/Types: deb deb-src/' /etc/apt/sources.list.d/debian.sources
  fi
  if [ -f /etc/apt/sources.list ] && grep -q '^deb ' /etc/apt/sources.list; then
    grep '^deb ' /etc/apt/sources.list | sed 's/^deb /deb-src /' \
      | $SUDO tee /etc/apt/sources.list.d/zz-deb-src.list >/dev/null
  fi
  $SUDO apt-get update -qq
fi
if ! apt-cache showsrc trilinos 2>/dev/null | grep -q '^Package: trilinos'; then
  echo "kokkos: WARNING: no trilinos source package reachable; falling back to Debian's Serial-only Kokkos" >&2
  $SUDO apt-get install -y -qq libtrilinos-kokkos-dev >/dev/null
  exit 0
fi
WORK="$(mktemp -d /tmp/kokkos-src.XXXXXX)"
trap 'rm -rf "$WORK"' EXIT
[ "$(id -u)" -ne 0 ] || chown _apt "$WORK"
cd "$WORK"
echo "kokkos: building Kokkos 3.4.01 (OpenMP+Serial) from Debian's trilinos source into $PREFIX (about 20 s)"
apt-get source --download-only -qq trilinos
echo "0ddb47784ba7b8a6b9a07a4822b33be508feb4ccd54301b2a5d10c9e54524b90  trilinos_13.2.0.orig.tar.gz" \
  | sha256sum -c --quiet - || echo "kokkos: WARNING: trilinos orig tarball differs from 13.2.0 (expected Kokkos 3.4.01)"
tar xzf trilinos_13.2.0.orig.tar.gz --strip-components=2 Trilinos-trilinos-release-13-2-0/packages/kokkos
rm -f trilinos_13.2.0.orig.tar.gz
cmake -S kokkos -B build -DCMAKE_BUILD_TYPE=Release -DCMAKE_INSTALL_PREFIX="$PREFIX" \
  -DCMAKE_CXX_STANDARD=17 -DKokkos_ENABLE_OPENMP=ON -DKokkos_ENABLE_SERIAL=ON \
  -DCMAKE_POSITION_INDEPENDENT_CODE=ON >/dev/null
cmake --build build -j"$(nproc)" >/dev/null
$SUDO cmake --install build >/dev/null
grep -q '^#define KOKKOS_ENABLE_OPENMP' "$CFG_H"
echo "kokkos: installed OpenMP+Serial Kokkos 3.4.01 to $PREFIX"
