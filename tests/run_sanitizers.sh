#!/usr/bin/env bash
# Builds triaxdem and its tests with AddressSanitizer and UndefinedBehaviorSanitizer (gcc) in build-asan/ and
# runs the suite there; any sanitizer report fails its test. Extra arguments go to ctest, e.g.
#   tests/run_sanitizers.sh                      # the whole suite but the hidden-effect diagnoses (long)
#   tests/run_sanitizers.sh -R Checkpoint        # a part
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${TRIAXDEM_SANITIZE_BUILD:-$root/build-asan}"
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DTRIAXDEM_SANITIZE=address,undefined \
  -DTRIAXDEM_PERF=OFF >/dev/null
cmake --build "$build" -j"$(nproc)" --target triaxdem triaxdem_tests
# Leak reports from the OpenMP runtime's thread pool at exit are not ours; everything else stops the test.
export ASAN_OPTIONS="detect_leaks=0:abort_on_error=1:${ASAN_OPTIONS:-}"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:${UBSAN_OPTIONS:-}"
# ctest runs as many tests as cores, and the two-thread ones then want twice the cores: spinning OpenMP
# threads made them up to 13 times slower than their one-thread twins (832 s against 64 s).
export OMP_WAIT_POLICY="${OMP_WAIT_POLICY:-passive}"
cd "$build"
if [ "$#" -eq 0 ]; then set -- -E HiddenEffect; fi
ctest -j"$(nproc)" --output-on-failure "$@"
