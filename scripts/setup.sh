#!/usr/bin/env bash
# Installs everything triaxdem needs on a fresh Debian 12 machine, from Debian's registry only.
# Idempotent and fast on re-run: apt skips what is installed, Kokkos is cached in $KOKKOS_PREFIX.
set -euo pipefail
export DEBIAN_FRONTEND=noninteractive
SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO="sudo"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"

pkgs=(cmake g++ make libeigen3-dev libhdf5-dev libcli11-dev libtomlplusplus-dev
      libgtest-dev googletest libbenchmark-dev python3-matplotlib python3-h5py python3-numpy
      clang libclang-rt-dev libomp-dev  # clang: the sanitizer and fuzz gates (tests/run_gates.sh)
      libopenmpi-dev openmpi-bin)       # optional for a build; jobs spread over ranks (docs/cluster.md)
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ "${#missing[@]}" -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
"$here/build_kokkos.sh"
