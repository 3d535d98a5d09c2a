#!/usr/bin/env bash
# Instructions per particle-step of triaxdem, LIGGGHTS and LAMMPS on the peer benchmark's packing, counted by
# valgrind's callgrind on one core: a count does not depend on what else the machine is doing, so it compares
# the codes where wall-clock ratios on a shared VM scatter. Each code runs N1 and N2 steps from the same
# start; the difference over (N2 - N1) x balls leaves out reading the packing and setting up (no neighbour
# rebuild happens in between: the logs are checked). Needs perf/peer_benchmark.sh run first (its packing
# and inputs) and valgrind. About 15 minutes.
#   perf/instruction_count.sh                 # N1=20 N2=40 BUILD=build WORK=runs/peer_benchmark PEERS="liggghts lammps"
# PEERS and CONFIG as perf/peer_benchmark.sh was run with (PEERS="": triaxdem alone).
# BYTES=1 also simulates the caches (callgrind --cache-sim, slower) and gives the bytes a particle-step brings from
# memory: the data misses of a last-level cache of LL_KB KiB (default 4096, far below the packing's arrays, so that
# the count is the step's streaming traffic, not what a larger cache happens to keep) times its 64-byte lines.
# Write-backs are not counted: an array written in a step adds its bytes twice to the memory's traffic, once here.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
. "$root/scripts/script_folders.sh"
n1="${N1:-20}"; n2="${N2:-40}"; peers="${PEERS-liggghts lammps}"; bytes="${BYTES:-0}"; ll_kb="${LL_KB:-4096}"
build="$(build_folder instruction_count)"; work="$(realpath -m "${WORK:-$root/runs/peer_benchmark}")"
for f in packing.data $(for code in $peers; do echo "in.$code"; done); do
  [ -f "$work/$f" ] || { echo "instruction_count: $work/$f missing: run perf/peer_benchmark.sh first"; exit 1; }
done
command -v valgrind >/dev/null || { echo "instruction_count: valgrind is needed (Debian package valgrind)"; exit 1; }
out="$work/instructions"
mkdir -p "$out"
cd "$out"
cp "$work/packing.data" .
balls=$(sed -n 's/^\([0-9]*\) atoms$/\1/p' packing.data)
count() {  # code steps -> instructions and last-level data misses collected
  local code=$1 n=$2
  case $code in
    triaxdem) cmd=("$build/triaxdem" run "$(realpath "${CONFIG:-$root/perf/configs/periodic_54k.toml}")" -o "$out/triaxdem_$n"
                    -n "$n" --overwrite) ;;
    liggghts) sed "s/^run .*/run $n/" "$work/in.liggghts" > "in.liggghts_$n"; cmd=(liggghts -in "in.liggghts_$n" -log none) ;;
    lammps) sed "s/^run .*/run $n/" "$work/in.lammps" > "in.lammps_$n"; cmd=(lmp -in "in.lammps_$n" -log none) ;;
  esac
  local sim=()
  [ "$bytes" = 1 ] && sim=(--cache-sim=yes "--LL=$((ll_kb * 1024)),16,64")
  OMP_NUM_THREADS=1 valgrind --tool=callgrind "${sim[@]}" --callgrind-out-file="callgrind.$code.$n" "${cmd[@]}" \
    > "$code.$n.log" 2>&1 || true
  if grep -q "unhandled instruction bytes: 0x62" "$code.$n.log"; then
    echo "instruction_count: valgrind cannot run $code's AVX-512 code (EVEX): count a build configured with" \
         "-DTRIAXDEM_X86_64=v3 (BUILD=...)" >&2; exit 1
  fi
  if [ "$code" = triaxdem ] && ! grep -q "^time loop:" "$code.$n.log"; then
    echo "instruction_count: $code did not run to its end under valgrind ($out/$code.$n.log)" >&2; exit 1
  fi
  if grep -q "^Neighbor list builds = [1-9]" "$code.$n.log" || grep -q "([2-9][0-9]* rebuilds)" "$code.$n.log"; then
    echo "instruction_count: $code rebuilt its neighbour list within $n steps; use fewer steps" >&2; exit 1
  fi
  # "instructions LLd-misses" (the data misses of the last-level cache: 0 without BYTES=1)
  local ir llm
  ir=$(sed -n 's/^==[0-9]*== Collected : \([0-9]*\).*$/\1/p' "$code.$n.log")
  llm=$(sed -n 's/^==[0-9]*== LLd misses: *\([0-9,]*\).*$/\1/p' "$code.$n.log" | tr -d ,)
  echo "$ir ${llm:-0}"
}
if [ "$bytes" = 1 ]; then
  echo "per particle-step, $balls balls, steps $n1 -> $n2, one core (callgrind, last-level cache $ll_kb KiB):" \
       "instructions, bytes from memory"
else
  echo "instructions per particle-step, $balls balls, steps $n1 -> $n2, one core (callgrind)"
fi
for code in triaxdem $peers; do
  first=$(count $code "$n1"); second=$(count $code "$n2")  # each exits on a failed run
  read -r ia la <<< "$first"; read -r ib lb <<< "$second"
  awk -v c="$code" -v ia="$ia" -v ib="$ib" -v la="$la" -v lb="$lb" -v s=$((n2 - n1)) -v n="$balls" -v b="$bytes" \
    'BEGIN { printf "  %-9s %6.0f", c, (ib - ia) / (s * n); if (b == 1) printf " %8.0f", 64 * (lb - la) / (s * n); print "" }'
done
