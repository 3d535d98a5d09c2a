#!/usr/bin/env bash
# Builds Kokkos 3.4.01 with CUDA (+ Serial on the host) from Debian bookworm's trilinos source, for a machine with
# the CUDA toolkit (nvcc on PATH or in /usr/local/cuda). Then configure triaxdem against it:
#   scripts/build_kokkos_cuda.sh                       # ARCH=AMPERE80 PREFIX=/opt/kokkos-3.4.01-cuda
#   SM=90 scripts/build_kokkos_cuda.sh                 # Hopper machine code: PREFIX=/opt/kokkos-3.4.01-cuda-sm90
#   cmake -S . -B build-cuda -DKokkos_ROOT=/opt/kokkos-3.4.01-cuda \
#         -DCMAKE_CXX_COMPILER=/opt/kokkos-3.4.01-cuda/bin/nvcc_wrapper && cmake --build build-cuda -j
# Kokkos 3.4 knows GPUs up to Ampere (AMPERE80, AMPERE86); its sm_80 code carries PTX, which the driver compiles for
# an H100 (sm_90) when the program starts, every time on a fresh machine. Kokkos >= 4.0 knows Hopper
# (-DKokkos_ARCH_HOPPER90=ON), and Debian 12 does not ship it; SM=90 keeps 3.4's AMPERE80 settings (a subset of
# what Hopper has) and emits sm_90 machine code instead of sm_80's, so that nothing is compiled at start.
# Two patches make 3.4.01 build with CUDA 13 (both are upstream fixes of later Kokkos releases, applied here with
# sed so that the source stays Debian's): the half-precision type, which no triaxdem kernel uses, is left out (CUDA 13
# dropped the conversions it relies on), and cudaMemPrefetchAsync takes a cudaMemLocation since CUDA 13.
set -euo pipefail
SM="${SM:-}"
PREFIX="${PREFIX:-/opt/kokkos-3.4.01-cuda${SM:+-sm$SM}}"
ARCH="${ARCH:-AMPERE80}"
CFG_H="$PREFIX/include/KokkosCore_config.h"
if [ -f "$PREFIX/lib/cmake/Kokkos/KokkosConfig.cmake" ] && grep -q '^#define KOKKOS_ENABLE_CUDA$' "$CFG_H" 2>/dev/null; then
  echo "kokkos-cuda: using cached install at $PREFIX"; exit 0
fi
[ -d /usr/local/cuda/bin ] && export PATH="/usr/local/cuda/bin:$PATH"
command -v nvcc >/dev/null || { echo "kokkos-cuda: nvcc not found (install the CUDA toolkit)" >&2; exit 1; }
export DEBIAN_FRONTEND=noninteractive
SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO="sudo"
if ! apt-cache showsrc trilinos 2>/dev/null | grep -q '^Package: trilinos'; then
  [ -f /etc/apt/sources.list.d/debian.sources ] &&
    $SUDO sed -i 's/^Types: deb$/Types: deb deb-src/' /etc/apt/sources.list.d/debian.sources
  $SUDO apt-get update -qq
fi
WORK="$(mktemp -d /tmp/kokkos-cuda-src.XXXXXX)"
trap 'rm -rf "$WORK"' EXIT
[ "$(id -u)" -ne 0 ] || chown _apt "$WORK"
cd "$WORK"
apt-get source --download-only -qq trilinos
tar xzf trilinos_13.2.0.orig.tar.gz --strip-components=2 Trilinos-trilinos-release-13-2-0/packages/kokkos
rm -f trilinos_13.2.0.orig.tar.gz
# nvcc_wrapper's default sm_35 is gone from CUDA >= 12; Kokkos passes its own -arch for the chosen ARCH.
sed -i 's/^default_arch="sm_35"/default_arch="${NVCC_WRAPPER_DEFAULT_ARCH:-sm_80}"/' kokkos/bin/nvcc_wrapper
sed -i 's/^#if !(defined(KOKKOS_COMPILER_CLANG) \&\& KOKKOS_COMPILER_CLANG < 900) \&\& \\$/#if 0 \&\& \\/' \
  kokkos/core/src/Cuda/Kokkos_Cuda_Half.hpp
python3 - kokkos/core/src/Cuda/Kokkos_CudaSpace.cpp <<'PY'
import sys
p = sys.argv[1]
s = open(p).read()
old = """    CUDA_SAFE_CALL(cudaMemPrefetchAsync(ptr, bytes, space.cuda_device(),
                                        space.cuda_stream()));"""
new = """#if CUDA_VERSION >= 13000
    cudaMemLocation loc{};
    loc.type = cudaMemLocationTypeDevice;
    loc.id = space.cuda_device();
    CUDA_SAFE_CALL(cudaMemPrefetchAsync(ptr, bytes, loc, 0, space.cuda_stream()));
#else
""" + old + "\n#endif"
assert old in s, "kokkos-cuda: Kokkos_CudaSpace.cpp is not 3.4.01's"
open(p, "w").write(s.replace(old, new))
PY
if [ -n "$SM" ]; then
  grep -q "CHECK_CUDA_ARCH($ARCH *sm_" kokkos/cmake/kokkos_arch.cmake ||
    { echo "kokkos-cuda: no CHECK_CUDA_ARCH($ARCH ...) in kokkos_arch.cmake" >&2; exit 1; }
  sed -i "s/CHECK_CUDA_ARCH($ARCH *sm_[0-9]*)/CHECK_CUDA_ARCH($ARCH sm_$SM)/" kokkos/cmake/kokkos_arch.cmake
fi
cmake -S kokkos -B build -DCMAKE_BUILD_TYPE=Release -DCMAKE_INSTALL_PREFIX="$PREFIX" -DCMAKE_CXX_STANDARD=17 \
  -DCMAKE_CXX_COMPILER="$PWD/kokkos/bin/nvcc_wrapper" -DKokkos_ENABLE_CUDA=ON -DKokkos_ENABLE_CUDA_LAMBDA=ON \
  -DKokkos_ENABLE_SERIAL=ON -DKokkos_ARCH_"$ARCH"=ON >/dev/null
cmake --build build -j"$(nproc)" >/dev/null
$SUDO cmake --install build >/dev/null
echo "kokkos-cuda: installed Kokkos 3.4.01 (CUDA $ARCH${SM:+ as sm_$SM} + Serial) to $PREFIX"
