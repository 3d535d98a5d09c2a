#!/usr/bin/env bash
# The gates after the suite (scripts/test.sh): one clang build with AddressSanitizer, UndefinedBehaviorSanitizer
# and libFuzzer's coverage (build-gates/), in which
#   1. the fast tests (unit tests and readers, one thread) run: any sanitizer report fails its test;
#   2. each fuzz harness runs for a fixed time (tests/fuzz/run_fuzz.sh): a finding fails the gate;
#   3. the program, built without MPI, refuses a start by mpirun.
#   tests/run_gates.sh [FUZZ_SECONDS]        (default 20 s per harness: six harnesses, three rounds on 2 cores)
# The whole suite under sanitizers (gcc, slower): tests/run_sanitizers.sh.
set -euo pipefail
secs="${1:-20}"
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${TRIAXDEM_GATES_BUILD:-$root/build-gates}"
# Line tables, not full debug information: a report's stack still names file and line, and the build (from scratch in
# CI) compiles about a fifth faster (calibrate.cpp 31.5 -> 25.9 s, its object 16.5 -> 3.8 MB).
cmake -S "$root" -B "$build" -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -gline-tables-only -DNDEBUG" -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O2 -gline-tables-only -DNDEBUG" \
  -DTRIAXDEM_FUZZ=ON -DTRIAXDEM_SANITIZE=address,undefined -DTRIAXDEM_PERF=OFF -DTRIAXDEM_MPI=OFF >/dev/null
targets=$(sed -n 's/^foreach(target \(.*\))$/\1/p' "$root/tests/fuzz/CMakeLists.txt")
cmake --build "$build" -j"$(nproc)" --target triaxdem triaxdem_tests $targets
# Leak reports from the OpenMP runtime's thread pool at exit are not ours; everything else stops the test.
export ASAN_OPTIONS="detect_leaks=0:abort_on_error=1:${ASAN_OPTIONS:-}"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:${UBSAN_OPTIONS:-}"
export OMP_WAIT_POLICY=passive
fast='^(Config|Measured|Misfit|Calibrate|PackingStore|CellBias|BlowUp|ContactLaw|Detection|Dynamics|WallServo|SimdLanes|Reduce|IoHdf5|Membrane[A-Za-z]*|PeriodicCell|Stress|Micro|Untrusted)\.|^Reference\.ContactLaws'
# Not the tests that pack and shear whole cells through the lab (the cell choice, the cell's bias, the state match
# and its bracket: 1-4 minutes each under the sanitizers): Calibrate.ParallelRunsEqualSequentialRuns runs that lab
# code here, and CellBias.* the bias's arithmetic.
echo "gates: the fast tests under ASan and UBSan"
(cd "$build" && ctest -j"$(nproc)" --output-on-failure -R "$fast" -E '\.omp2$|^Calibrate\.(AutoCell|MeasureMisfitCountsTheCellsBias|StateIsMatched|AMatchNear)')
echo "gates: fuzzing, ${secs} s per harness"
TRIAXDEM_FUZZ_BUILD="$build" TRIAXDEM_FUZZ_CONFIGURED=1 bash "$root/tests/fuzz/run_fuzz.sh" "$secs"
# Built without MPI (as this build is), a program that mpirun starts as one of several ranks must stop before it
# writes anything: each rank would run the whole job into the same folder.
echo "gates: a build without MPI refuses mpirun"
nompi="$build/nompi_check"; rm -rf "$nompi"
if OMPI_COMM_WORLD_SIZE=3 OMPI_COMM_WORLD_RANK=0 "$build/triaxdem" study "$root/configs/small" -o "$nompi" > "$build/nompi.log" 2>&1; then
  echo "gates: FAILED: a build without MPI ran a study that mpirun started as 3 ranks" >&2; exit 1
fi
grep -q "built without MPI" "$build/nompi.log" && [ ! -e "$nompi" ] ||
  { cat "$build/nompi.log"; echo "gates: FAILED: no clear refusal, or the folder was made" >&2; exit 1; }
