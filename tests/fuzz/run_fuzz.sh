#!/usr/bin/env bash
# Fuzzes every file triaxdem reads (config, measured CSV and HDF5, checkpoints, snapshots, study summaries,
# reference values, the specimen cache) for a bounded time each (default 60 s), with AddressSanitizer and
# UndefinedBehaviorSanitizer, starting from files of each kind. Prints the executions per
# target; a finding stops the target, leaves crash-* in the build folder and makes this script fail.
#   tests/fuzz/run_fuzz.sh [SECONDS]        (clang from Debian: apt-get install clang libomp-dev)
set -euo pipefail
secs="${1:-60}"
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="${TRIAXDEM_FUZZ_BUILD:-$root/build-fuzz}"
targets=$(sed -n 's/^foreach(target \(.*\))$/\1/p' "$root/tests/fuzz/CMakeLists.txt")
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
seed_files() {
  case "$1" in
    config) find "$root/configs" "$root/perf/configs" "$root/tests/data" -name '*.toml' ;;
    measured) find "$root/data" -name '*.csv' ;;
    checkpoint) echo "$seeds/pour/checkpoint.h5" ;;
    snapshot) find "$seeds/pour" -name 'snap_*.h5'; echo "$seeds/snapshot/micro_snapshot.h5" ;;
    tables) find "$seeds/tables" -type f ;;
  esac
}
for t in $targets; do
  t="${t#fuzz_}"
  corpus="$build/corpus_$t"
  mkdir -p "$corpus"
  i=0  # numbered: several folders hold files of the same name
  for f in $(seed_files "$t"); do cp "$f" "$corpus/seed$i-$(basename "$f")"; i=$((i + 1)); done
  echo "fuzz_$t: ${secs} s"
  (cd "$build" && ./tests/fuzz/fuzz_$t -max_total_time="$secs" -max_len=65536 -print_final_stats=1 \
      -timeout=10 -rss_limit_mb=4096 "$corpus" > "fuzz_$t.log" 2>&1) || status=1
  grep -E "stat::number_of_executed_units|stat::new_units_added|ERROR|SUMMARY" "$build/fuzz_$t.log" || true
done
[ "$status" -eq 0 ] && echo "fuzz: no findings" || echo "fuzz: FINDINGS, see $build/fuzz_*.log and $build/crash-*"
exit "$status"
