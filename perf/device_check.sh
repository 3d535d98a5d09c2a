#!/usr/bin/env bash
# The GPU check (docs/performance.md, "GPU"): everything a lent GPU's few minutes should answer, prepared on the
# CPU machine and run as one script there.
#   perf/device_check.sh prepare REF       # CPU build: the reference runs the device's are compared with
#   perf/device_check.sh pack BUILD DIR    # a CUDA build's programs and the Debian libraries they link, for `carry`
#   perf/device_check.sh run REF OUT       # any build: particle-steps/s, launch overhead, CPU-GPU agreement, tests
#   perf/device_check.sh table6 LOOP OUT   # any build: Table 6 at full scale with the closed loop's parameters
# BUILD: the build whose binaries run (default build); CPU_BUILD: the one that prepares (default build).
# TINY=1: a few hundred balls and steps, no membrane specimen and not the suite's tests, for CI on any build.
# SIZES: the benchmark's cube edges in balls (default "100 38 215"); CAL_LIMIT: seconds for the batched calibration
# (240; 0 leaves the stage out); CELLS: cells run as processes at once (16; 0 leaves the stage out); NCU: Nsight
# Compute's program for the device's bytes a particle-step (ncu; the stage is skipped where there is none).
# PARTS: which of the suite's tests run (default "kernels other"; "kernels" when device time is short), each part
# for at most TEST_LIMIT s (90); FULL_LIMIT: seconds for the full-scale test from nothing (60). BUDGET: seconds for
# the whole run (660), stages in order of value, what was reached in OUT/reached.txt; TABLE6=LOOP: the full-scale
# Table 6 of the table6 mode as the last stage, in what is left of the budget.
# Each stage has its own time limit, so that a slow stage costs its limit and not the rest.
set -uo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
. "$root/scripts/script_folders.sh"
mode="${1:-}"; ref="$(realpath -m "${2:-}")"
case "$mode" in prepare|pack|run|table6) [ -n "${2:-}" ] ;; *) false ;; esac ||
  { echo "usage: perf/device_check.sh prepare REF | pack BUILD DIR | run REF OUT | table6 LOOP OUT" >&2; exit 2; }
tiny="${TINY:-0}"
stage() { echo; echo "== $1 ($(date +%T))"; }
# The first interpreter with h5py compares the checkpoints too (Debian's, or the GPU machine's own).
py=python3
for p in /usr/bin/python3 python3; do "$p" -c "import h5py" 2>/dev/null && { py="$p"; break; }; done
small_cfg="$root/configs/small/S1_100kPa.toml"
# The membrane comparison: from a checkpoint inside consolidation to a few records into the shear.
small_start=2000; small_stop=10000

if [ "$mode" = pack ]; then
  # A GPU machine starts bare: it gets the programs, the shared libraries they link from this machine (all but the C
  # and C++ runtimes, which it has), and in DIR/build wrappers that look like a build folder to the run mode.
  from="$ref"; dir="$(realpath -m "${3:?usage: perf/device_check.sh pack BUILD DIR}")"
  fresh_folder device_check "$dir"; mkdir -p "$dir/bin" "$dir/lib" "$dir/build/tests"
  progs=("$from/triaxdem"); for t in "$from"/tests/triaxdem_tests_* "$from/perf/bench_engine"; do [ -x "$t" ] && [ -f "$t" ] && progs+=("$t"); done
  mkdir -p "$dir/build/perf"
  for p in "${progs[@]}"; do
    cp "$p" "$dir/bin/"; strip "$dir/bin/$(basename "$p")" 2>/dev/null || true  # symbols are a tenth of the size
    ldd "$p" | awk '$3 ~ /^\// { print $3 }' | grep -Ev '/(libc|libm|libstdc\+\+|libgcc_s|ld-linux[^/]*|libcuda)\.so' |
      xargs -r cp -Lu -t "$dir/lib/"
    name="$(basename "$p")"
    case "$name" in triaxdem) rel=build; up=.. ;; bench_engine) rel=build/perf; up=../.. ;; *) rel=build/tests; up=../.. ;; esac
    printf '#!/usr/bin/env bash\nhere="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"\nLD_LIBRARY_PATH="$here/%s/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" exec "$here/%s/bin/%s" "$@"\n' \
      "$up" "$up" "$name" > "$dir/$rel/$name"
    chmod +x "$dir/$rel/$name"
  done
  echo "device_check: packed ${#progs[@]} programs in $dir ($(du -sh "$dir" | cut -f1))"
  exit 0
fi

if [ "$mode" = prepare ]; then
  bin="$(realpath "${CPU_BUILD:-$root/build}")/triaxdem"
  mkdir -p "$ref"
  # The periodic cell of the calibration, sheared to 0.5% only (the whole path from the gas, about 20,000 steps).
  sed -e 's/^target_axial_strain_pct = .*/target_axial_strain_pct = 0.5/' -e 's/^record_strain_pct = .*/record_strain_pct = 0.025/' \
      -e 's/^snapshot_strains_pct = .*/snapshot_strains_pct = [0.5]/' "$root/configs/periodic/periodic_S1_100kPa.toml" \
      > "$ref/periodic.toml"
  [ "$tiny" = 1 ] && sed -i -e 's/^count = .*/count = 200/' -e 's/^size_mm = .*/size_mm = [18.0, 18.0, 18.0]/' "$ref/periodic.toml"
  "$bin" periodic "$ref/periodic.toml" -o "$ref/periodic_cpu" --overwrite > "$ref/periodic_cpu.log" 2>&1 ||
    { tail -n 5 "$ref/periodic_cpu.log"; exit 1; }
  if [ "$tiny" != 1 ]; then
    "$bin" triaxial "$small_cfg" -o "$ref/small_start" --overwrite --stop-at-step "$small_start" > "$ref/small_start.log" 2>&1
    [ $? -eq 3 ] || { tail -n 5 "$ref/small_start.log"; exit 1; }
    rm -rf "$ref/small_cpu"; cp -r "$ref/small_start" "$ref/small_cpu"
    "$bin" triaxial "$small_cfg" -o "$ref/small_cpu" --resume --stop-at-step "$small_stop" > "$ref/small_cpu.log" 2>&1
    [ $? -eq 3 ] || { tail -n 5 "$ref/small_cpu.log"; exit 1; }
  fi
  echo "device_check: references in $ref"
  exit 0
fi

if [ "$mode" = table6 ]; then
  # Table 6 at the paper's scale (issue 62, item 3): each material's parameters as perf/table6_loop.sh calibrated
  # them (LOOP/<material>_all/calibrate_*/calibrated.csv) put into configs/paper/, its three pressures run by the
  # membrane test, one specimen each, and set beside the lab's and the paper's own PFC3D values. BUDGET: seconds
  # for all (660: 12 minutes of device time less the start); a test that would start with under 60 s left is not
  # started, one cut by the budget is marked, and the table says what was reached. MATERIALS, PRESSURES: which.
  # TINY=1: tests/data/tiny_triaxial.toml at each pressure in place of configs/paper/ (the scripts' check on a CPU).
  loop="$ref"; out="$(realpath -m "${3:?usage: perf/device_check.sh table6 LOOP OUT}")"
  bin="$(build_folder device_check)/triaxdem"; budget="${BUDGET:-660}"
  mkdir -p "$out"; : > "$out/cases.csv"
  for m in ${MATERIALS:-S-1 S-2 S-3}; do
    cal="$(ls "$loop/${m}_all"/calibrate_*/calibrated.csv 2>/dev/null | tail -n 1)"
    [ -n "$cal" ] || echo "device_check: no $loop/${m}_all/calibrate_*/calibrated.csv: run perf/table6_loop.sh for $m first"
    for p in ${PRESSURES:-100 200 300}; do
      name="${m//-/}_${p}kPa"; cfg="$out/$name.toml"; left=$((budget - SECONDS))
      if [ "$tiny" = 1 ]; then
        sed -e "s/^material = .*/material = \"$m\"/" -e "s/^sigma3_kPa = .*/sigma3_kPa = $p/" \
          "$root/tests/data/tiny_triaxial.toml" > "$cfg"
      else cp "$root/configs/paper/$name.toml" "$cfg"; fi
      status="not calibrated"
      if [ -n "$cal" ]; then
        # Each calibrated parameter replaces its key's line in the config; one the config lacks stops the case.
        status="$("$py" - "$cal" "$cfg" <<'PY'
import csv, re, sys
cal, cfg = sys.argv[1], sys.argv[2]
text = open(cfg).read()
for row in csv.DictReader(open(cal)):
    text, n = re.subn(r"(?m)^%s = [^#\n]*" % re.escape(row["parameter"]), "%s = %s " % (row["parameter"], row["value"]), text)
    if n != 1:
        print("%s: no key %s to set" % (cfg, row["parameter"]))
        sys.exit()
open(cfg, "w").write(text)
print("ready")
PY
)"
      fi
      if [ "$status" = ready ] && [ "$left" -lt 60 ]; then status="not reached (${left} s left of $budget)"; fi
      if [ "$status" = ready ]; then
        stage "$m at $p kPa ($left s left of $budget)"
        t0=$SECONDS
        timeout -k 5 "$left" "$bin" triaxial "$cfg" -o "$out/$name" --overwrite > "$out/$name.log" 2>&1
        rc=$?; status=done; [ $rc = 124 ] && status="cut by the budget"; [ $rc != 0 ] && [ $rc != 124 ] && status="failed ($rc)"
        tr '\r' '\n' < "$out/$name.log" | grep -E "^time loop|q_peak" | tail -n 2
        # Each stage's nanoseconds a particle-step in each part (the host's share among them) in the log itself: the
        # runs' folders are too large to come back whole from a device.
        [ -f "$out/$name/timings.csv" ] && grep -E "^(stage|consolidation|shear)," "$out/$name/timings.csv"
        echo "$m,$p,$((SECONDS - t0)),$status,$cal" >> "$out/cases.csv"
      else
        echo "$m,$p,0,$status,$cal" >> "$out/cases.csv"
      fi
    done
  done
  "$py" - "$out" "$root/data" > "$out/table6.md" <<'PY'
import csv, os, sys
out, data = sys.argv[1], sys.argv[2]
def rows(path):
    return list(csv.DictReader(line for line in open(path) if not line.startswith("#")))
lab = {(r["material"], r["sigma3_kPa"]): float(r["q_peak_kPa"]) for r in rows(os.path.join(data, "tang2025_table6_peak.csv"))}
pfc = {(r["material"], r["sigma3_kPa"]): float(r["q_peak_kPa"]) for r in rows(os.path.join(data, "tang2025_table6_pfc3d.csv"))}
print("| material | sigma3 kPa | lab q_peak kPa | here kPa | error | paper's PFC3D kPa | its error | parameters | wall time | status |")
print("|---|---|---|---|---|---|---|---|---|---|")
errors, theirs = {}, {}
for m, p, secs, status, cal in csv.reader(open(os.path.join(out, "cases.csv"))):
    key, here = (m, p), None
    summary = os.path.join(out, "%s_%skPa" % (m.replace("-", ""), p), "summary.csv")
    if status == "done" and os.path.exists(summary):
        here = float(next(csv.DictReader(open(summary)))["q_peak_kPa"])
    params = "; ".join("%s %.4g" % (r["parameter"], float(r["value"])) for r in csv.DictReader(open(cal))) if cal else "-"
    err = 100 * (here / lab[key] - 1) if here is not None and key in lab else None
    their = 100 * (pfc[key] / lab[key] - 1) if key in pfc and key in lab else None
    if err is not None:
        errors.setdefault(m, []).append(abs(err)); theirs.setdefault(m, []).append(abs(their))
    print("| %s | %s | %s | %s | %s | %s | %s | %s | %dm%02ds | %s |" % (
        m, p, "%.1f" % lab[key] if key in lab else "-", "%.1f" % here if here is not None else "-",
        "%+.1f%%" % err if err is not None else "-", "%.1f" % pfc[key] if key in pfc else "-",
        "%+.1f%%" % their if their is not None else "-", params, int(secs) // 60, int(secs) % 60, status))
print()
every = [e for m in errors for e in errors[m]]
for m, e in list(errors.items()) + ([("all", every)] if len(errors) > 1 else []):
    t = [x for k in (errors if m == "all" else [m]) for x in theirs[k]]
    print("%s: mean |error| %.1f%%, at most %.1f%% over %d tests (the paper's PFC3D on the same: %.1f%%, %.1f%%)" % (
        m, sum(e) / len(e), max(e), len(e), sum(t) / len(t), max(t)))
if not every:
    print("no test reached its end")
PY
  cat "$out/table6.md"
  exit 0
fi

out="$(realpath -m "${3:?usage: perf/device_check.sh run REF OUT}")"
build="$(build_folder device_check)"; bin="$build/triaxdem"
mkdir -p "$out"; : > "$out/reached.txt"
failed=""
# The stages in order of value (issue 64): the kernel and reference tests, the million-ball benchmark, the batch
# beside one cell alone, a batched calibration, the CPU-GPU agreement, the rest of the suite, the full scale. BUDGET
# (seconds, 660: 12 minutes of device time less the start) bounds them all: each stage runs under the least of its
# own limit and what is left, a stage with less than its minimum left is not started, and reached.txt says which
# stages ran, were cut or were not reached, so a short window still brings back the most valuable figures.
budget="${BUDGET:-660}"
left() { echo $((budget - SECONDS)); }
# begin NAME MINIMUM: true where the stage starts (with at least MINIMUM s left); else the stage is marked not reached.
begin() {
  if [ "$(left)" -lt "$2" ]; then echo "not reached: $1 ($(left) s left of $budget)" | tee -a "$out/reached.txt"; return 1; fi
  stage "$1 ($(left) s left of $budget)"; current="$1"; started=$SECONDS
}
# limit SECONDS: the stage's own limit, or what is left of the budget where that is less.
limit() { local l; l=$(left); [ "$l" -lt "$1" ] && echo "$l" || echo "$1"; }
done_stage() { echo "ran: $current ($((SECONDS - started)) s)" >> "$out/reached.txt"; }

stage "device and build"
command -v nvidia-smi >/dev/null && nvidia-smi --query-gpu=name,memory.total,driver_version,clocks.max.sm --format=csv
"$bin" info || { echo "device_check: $bin does not start" >&2; exit 1; }

tests=$(find "$build/tests" -maxdepth 1 -type f -name 'triaxdem_tests_*' -perm -u+x 2>/dev/null | sort)
kernels='HotPath.*:Reduce.*:ContactLaw.*:Detection.*:Dynamics.*:BlowUp.*:Membrane*:Stress.*:Micro.*:SimdLanes.*:Reference.*:PeriodicCell.*:IoHdf5.*:Checkpoint.*:Determinism.*:TriaxialMeasures.*'
suite_part() {  # PART: the suite's kernel and reference tests, or the others
  local part=$1 filter="$kernels"
  [ "$part" = other ] && filter="-$kernels"
  begin "the suite's $part tests" 30 || return 0
  # The unit tests are one executable per layer (tests/CMakeLists.txt): each runs the part's tests it holds.
  # The tests that run the program as a child find it through TRIAXDEM_BINARY (a packed build is not where it was built).
  TRIAXDEM_BINARY="$bin" timeout -k 5 "$(limit "${TEST_LIMIT:-90}")" bash -c 'for t in $1; do "$t" --gtest_filter="$2"; done' _ "$tests" "$filter" \
    > "$out/tests_$part.log" 2>&1; echo "exit status $? (124: stopped at the limit)"
  echo "passed $(grep -c '^\[       OK \]' "$out/tests_$part.log"), failed $(grep -c '^\[  FAILED  \].*ms)$' "$out/tests_$part.log")"
  grep -E '^\[  FAILED  \].*ms\)$|^\[  SKIPPED \]' "$out/tests_$part.log"
  echo "slowest:"; sed -n 's/^\[       OK \] \(.*\) (\([0-9]*\) ms)$/\2 ms \1/p' "$out/tests_$part.log" | sort -rn | head -n 5
  done_stage
}
parts=" ${PARTS:-kernels other} "
[ -n "$tests" ] && [ "$tiny" != 1 ] && [[ "$parts" == *" kernels "* ]] && suite_part kernels

# Launch overhead: 64 balls, where a step's time is its launches and waits. Then the benchmark packing's sizes, the
# million first.
if [ "$tiny" = 1 ]; then overhead_steps=200; sizes="10 6"; steps=50; else overhead_steps=3000; sizes="${SIZES:-100 38 215}"; steps=200; fi
for k in $sizes; do
  begin "particle-steps/s at $((k * k * k)) balls ($steps steps)" 20 || continue
  BUILD="$build" WORK="$out/scaling" K="$k" STEPS="$steps" timeout -k 5 "$(limit "$([ "$k" -gt 150 ] && echo 120 || echo 100)")" bash "$root/perf/scaling.sh" | tail -n +2 || failed+=" scaling"
  rm -f "$out/scaling/out_k$k"/*.h5  # the snapshots of 10^7 balls are gigabytes
  done_stage
done
# The bytes a particle-step moves on the device (issue 64 item 2's measure there; the CPU counts lines brought into a
# cache, perf/instruction_count.sh BYTES=1): the step kernels' DRAM reads and writes by Nsight Compute's counters
# (NCU: its program, default ncu; --clock-control none leaves the clocks alone), on the first benchmark size's
# packing, a few steps after the lists are built. ncu replays each kernel for its counters: seconds, not minutes.
ncu="${NCU:-ncu}"; k="${sizes%% *}"; cfg="$out/scaling/k$k.toml"
if ! command -v "$ncu" > /dev/null; then echo "skipped: the device's bytes a particle-step (no $ncu here)" >> "$out/reached.txt"
elif [ -f "$cfg" ] && begin "bytes a particle-step on the device at $((k * k * k)) balls (ncu)" 40; then
  timeout -k 5 "$(limit 120)" "$ncu" --clock-control none --print-units base --csv --kernel-name-base demangled \
    --kernel-name 'regex:BallForce|Leapfrog' --launch-skip 8 --launch-count 8 \
    --metrics dram__bytes_read.sum,dram__bytes_write.sum,gpu__time_duration.sum \
    "$bin" run "$cfg" -n 12 --overwrite > "$out/ncu.log" 2>&1
  echo "exit status $? (124: stopped at the limit)"
  "$py" "$root/tools/ncu_bytes.py" "$out/ncu.log" "$((k * k * k))" || { tail -n 5 "$out/ncu.log"; failed+=" bytes"; }
  rm -f "$out/scaling/out_k$k"/*.h5
  done_stage
fi
if begin "launch overhead (64 balls, $overhead_steps steps)" 15; then
  BUILD="$build" WORK="$out/scaling" K=4 STEPS="$overhead_steps" timeout -k 5 "$(limit 60)" bash "$root/perf/scaling.sh"
  done_stage
fi

# The calibration's cells as one batch (host/engine/cell_batch.hpp), one launch per kernel for all; bench_engine's
# BM_CellBatch against one cell alone (BM_TimeLoop/9/1), 729 balls each.
if [ -x "$build/perf/bench_engine" ]; then
  batches='BM_TimeLoop/9/1|BM_CellBatch/(1|64|512)/9'; [ "$tiny" = 1 ] && batches='BM_CellBatch/4/5'
  if begin "calibration cells as one batch ($batches)" 30; then
    timeout -k 5 "$(limit "$([ "$tiny" = 1 ] && echo 60 || echo 150)")" "$build/perf/bench_engine" --benchmark_filter="$batches" \
      --benchmark_min_time=0.5 2>&1 | grep -E "^BM_" || failed+=" batch"
    done_stage
  fi
fi

# A calibration as users run it, its cells batched ([calibrate] batch auto): Table 6's S-1 on the shipped base, the
# prediction left out (TINY: the tiny synthetic case of the script checks).
if [ "${CAL_LIMIT:-240}" -gt 0 ] && begin "a batched calibration" 60; then
  cal_cfg="$root/configs/calibration/base.toml"; cal_data="$root/data/tang2025_table6_peak.csv"; cal_args="--material S-1"
  if [ "$tiny" = 1 ]; then
    sed -e 's/^ensemble = .*/ensemble = 1/' -e 's/^scatter_specimens = .*/scatter_specimens = 2/' \
        -e 's/^target_axial_strain_pct = .*/target_axial_strain_pct = 1.0/' "$root/tests/data/hidden_effects.toml" > "$out/cal_base.toml"
    "$bin" synth --config "$out/cal_base.toml" -o "$out/cal_data.csv" --overwrite --seed 1 --pressures 100 > "$out/synth.log" 2>&1
    cal_cfg="$out/cal_base.toml"; cal_data="$out/cal_data.csv"; cal_args="--free mu_s"
  fi
  timeout -k 5 "$(limit "${CAL_LIMIT:-240}")" "$bin" calibrate "$cal_data" --config "$cal_cfg" $cal_args --predict none -j 1 --yes \
    -o "$out/calibration" > "$out/calibration.log" 2>&1
  echo "exit status $? (124: stopped at the limit)"
  tr '\r' '\n' < "$out/calibration.log" | grep -E "in all .* particle-steps|mu_s = |the job took|job's" | tail -n 5
  done_stage
fi

if begin "periodic cell against the CPU's" 30; then
  timeout -k 5 "$(limit 60)" "$bin" periodic "$ref/periodic.toml" -o "$out/periodic" --overwrite > "$out/periodic.log" 2>&1 || failed+=" periodic-run"
  grep "^time loop" "$out/periodic.log"
  "$py" "$root/tools/compare_runs.py" "$ref/periodic_cpu" "$out/periodic" || failed+=" periodic"
  done_stage
fi

if [ "$tiny" != 1 ] && begin "membrane triaxial test against the CPU's (steps $small_start-$small_stop)" 30; then
  rm -rf "$out/small"; cp -r "$ref/small_start" "$out/small"
  timeout -k 5 "$(limit 60)" "$bin" triaxial "$small_cfg" -o "$out/small" --resume --stop-at-step "$small_stop" > "$out/small.log" 2>&1
  grep "^time loop" "$out/small.log"
  "$py" "$root/tools/compare_runs.py" "$ref/small_cpu" "$out/small" || failed+=" membrane"
  done_stage
fi

# Today's other way of running many calibration cells on one GPU: separate processes, each its own context and
# launches, the figure the batch is set against.
cells="${CELLS:-16}"; [ "$tiny" = 1 ] && cells=2
if [ "$cells" -gt 0 ] && begin "$cells periodic cells as $cells processes at once" 30; then
  t0=$(date +%s.%N)
  for i in $(seq "$cells"); do
    timeout -k 5 "$(limit 120)" "$bin" periodic "$ref/periodic.toml" -o "$out/cells/c$i" --overwrite > "$out/cells_$i.log" 2>&1 &
  done
  wait
  wall=$(awk -v s="$t0" -v e="$(date +%s.%N)" 'BEGIN { print e - s }')
  # Each time loop's steps and particle-steps/s; the wall time holds the processes' starts, preparation and output too.
  cat "$out"/cells_*.log | sed -n 's/^time loop.*: \([0-9]*\) steps.*; \([0-9.e+]*\) particle-steps\/s.*/\1 \2/p' |
    awk -v w="$wall" -v n="$(awk -F' = ' '$1 == "count" { print $2 }' "$ref/periodic.toml")" -v c="$cells" \
    '{ s += $1; r += $2; k++ }
     END { if (k == 0) { printf "%d cells of %d balls: none finished within its limit (%.1f s wall)\n", c, n, w; exit }
           printf "%d cells of %d balls (%d finished): %.1f s wall for %d steps in all, %.3g particle-steps/s " \
             "together; each time loop %.3g particle-steps/s on average\n", c, n, k, w, s, s * n / w, r / k }'
  rm -rf "$out/cells"
  done_stage
fi

[ -n "$tests" ] && [ "$tiny" != 1 ] && [[ "$parts" == *" other "* ]] && suite_part other

if [ -n "${TABLE6:-}" ]; then
  # Table 6 at full scale from the loop's calibration (the table6 mode), with what is left of the budget.
  if begin "Table 6 at full scale (the table6 mode)" 120; then
    BUDGET="$(left)" bash "$0" table6 "$TABLE6" "$out/table6"
    done_stage
  fi
elif [ "$tiny" != 1 ]; then
  if begin "full scale: the paper's S-1 test (53,704 beads) from nothing" 60; then
    timeout -k 5 "$(limit "${FULL_LIMIT:-60}")" "$bin" triaxial "$root/configs/paper/S1_100kPa.toml" -o "$out/full" > "$out/full.log" 2>&1
    echo "exit status $? (124: stopped at the limit)"
    tr '\r' '\n' < "$out/full.log" | grep -E "^specimen: layer|time loop|q_peak" | tail -n 12
    tr '\r' '\n' < "$out/full.log" | grep -E "layer|consolidat|shear|axial" | tail -n 1
    [ -f "$out/full/timings.csv" ] && cat "$out/full/timings.csv"
    done_stage
  fi
fi
stage "done: $SECONDS s of $budget; reached.txt:"
cat "$out/reached.txt"
[ -z "$failed" ] || { echo "device_check: differed or failed:$failed"; exit 1; }
