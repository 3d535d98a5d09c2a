#!/usr/bin/env bash
# Fuzzes every file triaxdem reads (config, measured CSV and HDF5, checkpoints, snapshots, study summaries,
# reference values, the specimen cache) for a bounded time each (default 60 s), one harness per core at a time
# (TRIAXDEM_FUZZ_JOBS), with AddressSanitizer and UndefinedBehaviorSanitizer, starting from files of each kind.
# Prints the executions per target; a finding stops the target, leaves crash-* in the build folder and makes this
# script fail.
#   tests/fuzz/run_fuzz.sh [SECONDS [TARGET...]]   (clang from Debian: apt-get install clang libomp-dev)
set -euo pipefail
secs="${1:-60}"
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="$(realpath -m "${TRIAXDEM_FUZZ_BUILD:-$root/build-fuzz}")"
targets=$(sed -n 's/^foreach(target \(.*\))$/\1/p' "$root/tests/fuzz/CMakeLists.txt")
# Which to run: those named after SECONDS, else all but fuzz_hdf5_raw, which finds libhdf5's own memory errors
# (tests/fuzz/libhdf5_crashes) and so fails runs for what triaxdem cannot mend.
shift || true
run_targets="${*:-$(echo "$targets" | tr ' ' '\n' | grep -v '^fuzz_hdf5_raw$' | tr '\n' ' ')}"
if [ "${TRIAXDEM_FUZZ_CONFIGURED:-0}" != 1 ]; then  # tests/run_gates.sh has built them in its own folder
  cmake -S "$root" -B "$build" -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DTRIAXDEM_FUZZ=ON -DTRIAXDEM_SANITIZE=address,undefined -DTRIAXDEM_TESTS=OFF -DTRIAXDEM_PERF=OFF >/dev/null
  cmake --build "$build" -j"$(nproc)" --target triaxdem $targets
fi
status=0
# Seeds: the shipped files for the text parsers; for the file readers, files of each kind written by triaxdem (a
# short pour: checkpoints, snapshots) and by make_seeds.py (a snapshot with contacts, the small tables).
seeds="$build/fuzz_seeds"
rm -rf "$seeds" && mkdir -p "$seeds/pour"
cat > "$seeds/pour.toml" <<'TOML'
[run]
name = "pour"
series_every = 100
snapshot_every = 100
checkpoint_every = 100
[particles]
count = 60
diameter_mm = 2.0
[box]
size_mm = [10.0, 10.0, 16.0]
walls = true
[material]
emod_Pa = 1.0e8
mu_s = 0.3
mu_r = 0.05
[solver]
gravity = [0.0, 0.0, -2000.0]
TOML
"$build/triaxdem" run "$seeds/pour.toml" -n 300 -o "$seeds/pour" >/dev/null
/usr/bin/python3 "$root/tests/fuzz/make_seeds.py" "$seeds"
# The raw harness's first byte picks the reader: 0 checkpoint, 1 snapshot, 2 measured HDF5.
mkdir -p "$seeds/raw"
(printf '\000'; cat "$seeds/pour/checkpoint.h5") > "$seeds/raw/checkpoint"
i=0
for f in "$seeds"/pour/snap_*.h5 "$seeds/snapshot/micro_snapshot.h5"; do
  (printf '\001'; cat "$f") > "$seeds/raw/snapshot$i"; i=$((i + 1))
done
(printf '\002'; cat "$seeds/measured.h5") > "$seeds/raw/measured"
seed_files() {
  case "$1" in
    config) find "$root/configs" "$root/perf/configs" "$root/tests/data" -name '*.toml' ;;
    measured) find "$root/data" -name '*.csv' ;;
    tables) find "$seeds/tables" -type f ;;
    hdf5_raw) find "$seeds/raw" -type f ;;
    *) ;;  # the structure-aware harnesses make their files from any bytes
  esac
  # Inputs that once failed a harness, kept as regression tests: the corpus runs first.
  [ -d "$root/tests/fuzz/regressions/$1" ] && find "$root/tests/fuzz/regressions/$1" -type f
  return 0
}
# libhdf5 sizes its metadata buffers from the file and handles a failed allocation as a damaged file; ASan
# stops at such an allocation unless malloc may return null, as it does outside ASan (three findings of the
# first run, all in H5C_protect: tests/fuzz/regressions). An allocation of ours that fails throws bad_alloc,
# which the harnesses do not catch: still a finding.
export ASAN_OPTIONS="allocator_may_return_null=1:detect_leaks=0:${ASAN_OPTIONS:-}"
# One harness: a fresh corpus from the seeds (as CI's fresh clone has), its run, then its summary lines at once, so
# that harnesses running side by side do not interleave them; its status goes to a file for the end.
run_one() {
  local t="${1#fuzz_}" i=0 f rc=0
  local corpus="$build/corpus_$t"
  rm -rf "$corpus" && mkdir -p "$corpus"
  for f in $(seed_files "$t"); do cp "$f" "$corpus/seed$i-$(basename "$f")"; i=$((i + 1)); done  # numbered: names repeat
  (cd "$build" && ./tests/fuzz/fuzz_$t -max_total_time="$secs" -max_len=65536 -print_final_stats=1 \
      -timeout=10 -rss_limit_mb=4096 "$corpus" > "fuzz_$t.log" 2>&1) || rc=1
  { echo "fuzz_$t: ${secs} s"; grep -E "stat::number_of_executed_units|stat::new_units_added|ERROR|SUMMARY" \
      "$build/fuzz_$t.log" || true; }
  echo "$rc" > "$build/fuzz_$t.status"  # fuzz_<name>.status, as the loops below name it
}
# A harness is one process on one core: as many run at once as there are cores, each for its full time.
at_once="${TRIAXDEM_FUZZ_JOBS:-$(nproc)}"
for t in $run_targets; do
  rm -f "$build/${t}.status"
  while [ "$(jobs -rp | wc -l)" -ge "$at_once" ]; do wait -n || true; done
  run_one "$t" &
done
wait
for t in $run_targets; do
  [ "$(cat "$build/${t}.status" 2>/dev/null || echo 1)" = 0 ] || status=1
done
[ "$status" -eq 0 ] && echo "fuzz: no findings" || echo "fuzz: FINDINGS, see $build/fuzz_*.log and $build/crash-*"
exit "$status"
