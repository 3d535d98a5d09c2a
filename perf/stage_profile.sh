#!/usr/bin/env bash
# Where the jobs users run spend their time, stage by stage, on this machine in one run:
#  1. the membrane triaxial test of CONFIG, its specimen built afresh: per stage (specimen layers, consolidation,
#     shear) the particle-steps per second and the nanoseconds per particle-step in each part of the step (rebuild,
#     ball-ball, ball-wall, membrane, gather + integration, boundaries) and in the host's work between steps (servo,
#     records, output), from the job's timings.csv;
#  2. the kernel benchmark beside it: the periodic packing of perf/configs/periodic_54k.toml at about the same ball
#     count, BENCH_STEPS steps, and each stage's speed as a share of the benchmark's;
#  3. a diagnosis of three synthetic tests made from DIAG_CONFIG (or of DATA), with NP workers: its wall time, its
#     runs and their mean length, and how busy the workers were (the rest they waited for a batch's longest run).
#   perf/stage_profile.sh     # CONFIG=configs/paper/S1_100kPa.toml DIAG_CONFIG=configs/calibration/base.toml
#                             # BENCH_STEPS=1000 NP=$(nproc) PRESSURES="100 200 300" (kPa, of the synthetic tests)
#                             # BUILD=build WORK=runs/stage_profile
# SKIP="triaxial" or SKIP="diagnosis" leaves a part out. The full-scale test takes 20-60 minutes on 2 cores and the
# default diagnosis hours: run it in the background with its log in a file.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
. "$root/scripts/script_folders.sh"
build="$(build_folder stage_profile)"; work="$(realpath -m "${WORK:-$root/runs/stage_profile}")"
config="$(realpath "${CONFIG:-$root/configs/paper/S1_100kPa.toml}")"
diag_config="$(realpath "${DIAG_CONFIG:-$root/configs/calibration/base.toml}")"
np="${NP:-$(nproc)}"; bench_steps="${BENCH_STEPS:-1000}"; skip="${SKIP:-}"; pressures="${PRESSURES:-100 200 300}"
tdem="$build/triaxdem"
[ -x "$tdem" ] || { echo "stage_profile: build triaxdem first ($tdem)"; exit 1; }
py=python3; [ -x /usr/bin/python3 ] && py=/usr/bin/python3
fresh_folder stage_profile "$work"
export OMP_PROC_BIND=spread OMP_PLACES=threads

if [[ " $skip " != *" triaxial "* ]]; then
  echo "== triaxial test: $config ($np threads; log $work/triaxial.log)"
  OMP_NUM_THREADS="$np" "$tdem" triaxial "$config" -o "$work/triaxial" > "$work/triaxial.log" 2>&1
  # The benchmark's jittered cubic array at the shear stage's ball count: k^3 balls at a pitch of 1.99 mm.
  balls=$(awk -F, '$1 == "shear" { print $2 }' "$work/triaxial/timings.csv")
  k=$(awk -v n="$balls" 'BEGIN { k = int(n ^ (1 / 3) + 0.5); print k < 2 ? 2 : k }')
  edge=$(awk -v k="$k" 'BEGIN { printf "%.4f", k * 1.99 }')
  sed -e "s/^count = .*/count = $((k * k * k))/" -e "s/^size_mm = .*/size_mm = [$edge, $edge, $edge]/" \
      "$root/perf/configs/periodic_54k.toml" > "$work/bench.toml"
  echo "== kernel benchmark: $((k * k * k)) balls, $bench_steps steps"
  OMP_NUM_THREADS="$np" "$tdem" run "$work/bench.toml" -o "$work/bench" -n "$bench_steps" > "$work/bench.log" 2>&1
  "$py" - "$work/triaxial/timings.csv" "$work/bench/timings.csv" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
bench = list(csv.DictReader(open(sys.argv[2])))[0]
parts = ["rebuild", "ball_ball", "ball_wall", "membrane", "gather_integrate", "boundaries", "host"]
pairs = ["ball_pairs_per_ball", "wall_pairs_per_ball"]
rate0 = float(bench["particle_steps_per_s"])
print("%-20s %7s %8s %8s %9s %6s | %s" % ("stage", "balls", "steps", "wall_s", "psteps/s", "bench",
      " ".join("%9s" % p[:9] for p in parts) + " | pairs/ball: balls walls"))
for r in rows + [dict(bench, stage="benchmark")]:
    rate = float(r["particle_steps_per_s"])
    print("%-20s %7s %8s %8.1f %9.3g %6.2f | %s | %5.2f %5.2f" % (r["stage"], r["balls"], r["steps"],
          float(r["wall_s"]), rate, rate / rate0, " ".join("%9.1f" % float(r[p + "_ns"]) for p in parts),
          float(r[pairs[0]]), float(r[pairs[1]])))
print("(the parts in ns per particle-step; pairs/ball: candidate pairs in the contact lists per ball at the end)")
total = sum(float(r["wall_s"]) for r in rows)
steps = sum(int(r["steps"]) for r in rows)
print("all stages: %d steps in %.1f s; the benchmark: %s balls at %.3g particle-steps/s" %
      (steps, total, bench["balls"], rate0))
PY
fi

if [[ " $skip " != *" diagnosis "* ]]; then
  data="${DATA:-}"
  if [ -z "$data" ]; then
    data="$work/diagnosis_data.csv"
    # shellcheck disable=SC2086  # the pressures are words
    "$tdem" synth --config "$diag_config" -o "$data" --extension none --seed 1 --pressures $pressures \
      > "$work/synth.log" 2>&1
  fi
  echo "== diagnosis of $data with $diag_config, $np workers (log $work/diagnosis.log)"
  start=$SECONDS
  OMP_NUM_THREADS=1 "$tdem" diagnose "$data" --config "$diag_config" -o "$work/diagnosis" -j "$np" \
    > "$work/diagnosis.log" 2>&1
  echo "wall time: $((SECONDS - start)) s"
  grep -E "^diagnose: .*(runs|pieces)" "$work/diagnosis.log"
fi
