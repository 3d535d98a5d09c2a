#!/usr/bin/env bash
# Fuzzes the config and measured-data parsers for a bounded time each (default 60 s), with AddressSanitizer
# and UndefinedBehaviorSanitizer, starting from the shipped configs and data. Prints the executions per
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
  cmake --build "$build" -j"$(nproc)" --target $targets
fi
status=0
for t in config measured; do
  corpus="$build/corpus_$t"
  mkdir -p "$corpus"
  # Seeds: the shipped files (numbered: several folders hold files of the same name).
  if [ "$t" = config ]; then seeds=$(find "$root/configs" "$root/perf/configs" "$root/tests/data" -name '*.toml')
  else seeds=$(find "$root/data" -name '*.csv'); fi
  i=0
  for f in $seeds; do cp "$f" "$corpus/seed$i-$(basename "$f")"; i=$((i + 1)); done
  echo "fuzz_$t: ${secs} s"
  (cd "$build" && ./tests/fuzz/fuzz_$t -max_total_time="$secs" -max_len=16384 -print_final_stats=1 \
      -timeout=10 "$corpus" > "fuzz_$t.log" 2>&1) || status=1
  grep -E "stat::number_of_executed_units|stat::new_units_added|ERROR|SUMMARY" "$build/fuzz_$t.log" || true
done
[ "$status" -eq 0 ] && echo "fuzz: no findings" || echo "fuzz: FINDINGS, see $build/fuzz_*.log and $build/crash-*"
exit "$status"
