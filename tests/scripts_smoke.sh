#!/usr/bin/env bash
# Every script in perf/ and tools/ run on a tiny case, so that a change that breaks one fails the suite. Each gets
# seconds of work on one core; a script passes when it exits 0 and writes what it says it writes. A script in perf/ or
# tools/ without a line here fails the check at the end.
#   tests/scripts_smoke.sh [BUILD] [PART]         # default build; PART: all (default), tools or diagnoses
# The two parts take about as long, so that ctest runs them side by side on two cores (Scripts.* in
# tests/CMakeLists.txt): the tools, the benchmarks and the specimen scripts, then the scripts that run diagnoses.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="$(realpath "${1:-$root/build}")"
part="${2:-all}"
case "$part" in all|tools|diagnoses) ;; *) echo "scripts_smoke: PART is all, tools or diagnoses, not '$part'" >&2; exit 2 ;; esac
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
export OMP_NUM_THREADS=1 OMP_WAIT_POLICY=passive
# Debian's interpreter: python3-matplotlib and python3-h5py are installed for it (scripts/setup.sh).
py=python3; [ -x /usr/bin/python3 ] && py=/usr/bin/python3
tdem="$build/triaxdem"
ran=()
check() {  # NAME COMMAND...: runs it, its output in the log, and stops the check on failure
  local name=$1; shift
  echo "== $name"
  local start=$SECONDS
  if ! "$@" > "$work/$(basename "$name").log" 2>&1; then
    tail -n 20 "$work/$(basename "$name").log"
    echo "scripts_smoke: $name failed: $*" >&2
    exit 1
  fi
  echo "   ok ($((SECONDS - start)) s)"
  ran+=("$name")
}
exists() { for f in "$@"; do [ -s "$f" ] || { echo "scripts_smoke: $f not written" >&2; exit 1; }; done; }

# The inputs: a tiny membrane triaxial test, a study of it, a tiny calibration with its membrane prediction.
base="$work/base.toml"
sed -e 's/^ensemble = .*/ensemble = 1/' -e 's/^scatter_specimens = .*/scatter_specimens = 2/' \
    -e 's/^target_axial_strain_pct = .*/target_axial_strain_pct = 1.0/' "$root/tests/data/hidden_effects.toml" > "$base"
if [ "$part" != diagnoses ]; then
  "$tdem" triaxial "$root/tests/data/tiny_triaxial.toml" -o "$work/tiny" > "$work/tiny.log" 2>&1
  "$tdem" synth --config "$base" -o "$work/data.csv" --extension none --seed 1 --pressures 100 > "$work/synth.log" 2>&1
  "$tdem" calibrate "$work/data.csv" --config "$base" --predict "$root/tests/data/tiny_triaxial.toml" -o "$work/cal" -j 1 \
    > "$work/cal.log" 2>&1
  cal="$(ls -d "$work"/cal/calibrate_*)"

  check tools/schedule_projection.py "$py" "$root/tools/schedule_projection.py" "$cal/pools.csv" --ranks 2,64
  check tools/plot_triaxial.py "$py" "$root/tools/plot_triaxial.py" "$work/tiny" -o "$work/triaxial.png"
  exists "$work/triaxial.png"
  check tools/plot_micro.py "$py" "$root/tools/plot_micro.py" "$work/tiny"
  exists "$work/tiny/micro_anisotropy.png"
  check tools/stress_measures.py "$py" "$root/tools/stress_measures.py" "$work/tiny"
  check tools/compare_micro.py "$py" "$root/tools/compare_micro.py" "$work/tiny"
  check tools/compare_runs.py "$py" "$root/tools/compare_runs.py" "$work/tiny" "$work/tiny"
  "$tdem" study "$root/tests/data/tiny_triaxial.toml" -o "$work/study" -j 1 -t 1 > "$work/study.log" 2>&1
  check tools/plot_study.py "$py" "$root/tools/plot_study.py" "$work/study" -o "$work/study.png"
  exists "$work/study.png"
  printf '# doc\n<!-- docs_table tiny -->\nold\n<!-- /docs_table tiny -->\nkept\n' > "$work/doc.md"
  check tools/docs_table.py "$py" "$root/tools/docs_table.py" "$work/study" --doc "$work/doc.md" --block tiny
  grep -q "^| tiny_triaxial | " "$work/doc.md" && grep -q "^kept$" "$work/doc.md" && ! grep -q "^old$" "$work/doc.md" ||
    { cat "$work/doc.md"; echo "scripts_smoke: docs_table did not replace its block" >&2; exit 1; }
  check tools/plot_calibration.py "$py" "$root/tools/plot_calibration.py" "$cal" -o "$work/calibration.png"
  check tools/plot_prediction.py "$py" "$root/tools/plot_prediction.py" "$cal" -o "$work/prediction.png"
  exists "$work/calibration.png" "$work/prediction.png"
  check tools/sweep_table.py "$py" "$root/tools/sweep_table.py" \
    --level lab="$root/data/sweeps/hidden_sweep_lab_cellbias_seeds1-6.csv"
  grep -q "identifiable cases named right: \*\*14 of 14\*\*" "$work/sweep_table.py.log" ||
    { cat "$work/sweep_table.py.log"; echo "scripts_smoke: sweep_table miscounted the shipped lab-like sweep" >&2; exit 1; }

  # The results page from its artifacts, then from a copy of them with one figure changed: the check must fail.
  check tools/results_page.py "$py" "$root/tools/results_page.py" --check
  mkdir -p "$work/results/data/sweeps" "$work/results/docs"
  cp -r "$root/data/runs" "$root/data/results" "$work/results/data/" && cp -r "$root/data/sweeps/identification" "$root/data/sweeps/coverage" \
    "$root/data/sweeps/plan" "$root/data/sweeps/compression" "$root/data/sweeps/psd" \
    "$root/data/sweeps/joint" "$root/data/sweeps/preparation" "$root/data/sweeps/inertial_scan_base_8specimens.csv" \
    "$work/results/data/sweeps/" && cp -r "$root/docs/results.md" "$root/docs/device_runs" "$work/results/docs/"
  sed -i "s/,31.348,/,41.348,/" "$work/results/data/runs/S1_table6_periodic/prediction.csv"  # the error at 100 kPa
  ! "$py" "$root/tools/results_page.py" --root "$work/results" --check > "$work/results_changed.log" 2>&1 &&
    grep -q "is not what its artifacts give" "$work/results_changed.log" ||
    { cat "$work/results_changed.log"; echo "scripts_smoke: the results page passed with a changed artifact" >&2; exit 1; }
  check perf/scaling.sh env BUILD="$build" WORK="$work/scaling" K=4 STEPS=20 CSV="$work/scaling.csv" \
    bash "$root/perf/scaling.sh"
  # The results page's row: its date, commit and machine, then the size's figures.
  grep -Eq "^[0-9]{4}-[0-9]{2}-[0-9]{2},[0-9a-f+]+,[^,]+,[0-9]+,20,64,[0-9.e+]+," "$work/scaling.csv" ||
    { cat "$work/scaling.csv"; echo "scripts_smoke: scaling wrote no CSV row" >&2; exit 1; }
  # The tiny calibration above, again from its packing store: the plan, a first and a second job, one row each.
  check perf/time_to_answer.sh env BUILD="$build" WORK="$work/answer" CASES=tiny JOBS=1 STORE="$work/cal" \
    bash "$root/perf/time_to_answer.sh"
  [ "$(grep -c '^| tiny (' "$work/time_to_answer.sh.log")" = 2 ] ||
    { cat "$work/time_to_answer.sh.log"; echo "scripts_smoke: time_to_answer gave no row per pass" >&2; exit 1; }
  # Issue 87: a misspelt case removed WORK's files before it was refused; a WORK the script did not make is refused and
  # kept; a BUILD that does not exist is named with BUILD=.
  mkdir -p "$work/user_folder" && touch "$work/user_folder/keep"
  for cases in foo tiny; do
    ! env BUILD="$build" WORK="$work/user_folder" CASES=$cases bash "$root/perf/time_to_answer.sh" > "$work/tta_$cases.log" 2>&1 &&
      [ -f "$work/user_folder/keep" ] ||
      { cat "$work/tta_$cases.log"; echo "scripts_smoke: time_to_answer removed a folder it did not make" >&2; exit 1; }
  done
  grep -q "no case 'foo'" "$work/tta_foo.log" && grep -q "holds files this script did not make" "$work/tta_tiny.log" ||
    { cat "$work"/tta_*.log; echo "scripts_smoke: time_to_answer's refusals unclear" >&2; exit 1; }
  ! env BUILD=/nonexistent CASES=tiny bash "$root/perf/time_to_answer.sh" > "$work/tta_build.log" 2>&1 &&
    grep -q "BUILD=/nonexistent: no such folder" "$work/tta_build.log" ||
    { cat "$work/tta_build.log"; echo "scripts_smoke: a missing BUILD is not named" >&2; exit 1; }
  check perf/specimen_settling.sh env BUILD="$build" WORK="$work/settling" CONFIG="$root/tests/data/tiny_triaxial.toml" \
    SEEDS=1 NP=1 bash "$root/perf/specimen_settling.sh"
  grep -q "^q_peak kPa " "$work/specimen_settling.sh.log" ||
    { cat "$work/specimen_settling.sh.log"; echo "scripts_smoke: specimen_settling compared nothing" >&2; exit 1; }
  # Nsight Compute is on GPU machines only: a stand-in prints what ncu printed for two step kernels, so that the
  # bytes stage and tools/ncu_bytes.py run here.
  printf '#!/bin/sh\ncat "%s/tests/data/ncu_sample.csv"\n' "$root" > "$work/ncu" && chmod +x "$work/ncu"
  check perf/device_check.sh bash -c "TINY=1 CPU_BUILD='$build' bash '$root/perf/device_check.sh' prepare '$work/dc_ref' &&
    bash '$root/perf/device_check.sh' pack '$build' '$work/dc_pack' &&
    TINY=1 NCU='$work/ncu' BUILD='$work/dc_pack/build' bash '$root/perf/device_check.sh' run '$work/dc_ref' '$work/dc'"
  grep -q "^ran: a batched calibration" "$work/dc/reached.txt" ||
    { cat "$work/dc/reached.txt"; echo "scripts_smoke: device_check ran no batched calibration" >&2; exit 1; }
  grep -q "^ran: bytes a particle-step" "$work/dc/reached.txt" &&
    grep -q "^a particle-step (1 steps of 1000 balls): 691214 bytes read, 344862 written" "$work/device_check.sh.log" ||
    { cat "$work/dc/reached.txt"; echo "scripts_smoke: device_check's bytes stage read no step" >&2; exit 1; }
  check tools/ncu_bytes.py "$py" "$root/tools/ncu_bytes.py" "$root/tests/data/ncu_sample.csv" 1000000
  # What ncu printed on an H200 (30 November, Kokkos 3.4, 10^6 balls): its kernel names drop namespaces and write the
  # anonymous one as <unnamed>; the step kernel must still be found and the step's bytes summed.
  "$py" "$root/tools/ncu_bytes.py" "$root/tests/data/ncu_h200.csv" 1000000 > "$work/ncu_h200.log" 2>&1 &&
    grep -q "^a particle-step (4 steps of 1000000 balls): 804 bytes read, 433 written" "$work/ncu_h200.log" ||
    { cat "$work/ncu_h200.log"; echo "scripts_smoke: ncu_bytes found no step in the H200's names" >&2; exit 1; }
  # A window of no time reaches no stage, and says so for each (the budget's bookkeeping, at no cost).
  TINY=1 BUDGET=0 BUILD="$build" bash "$root/perf/device_check.sh" run "$work/dc_ref" "$work/dc0" > "$work/dc0.log" 2>&1
  [ "$(grep -c '^not reached: ' "$work/dc0/reached.txt")" -ge 6 ] && ! grep -q '^ran: ' "$work/dc0/reached.txt" ||
    { cat "$work/dc0.log"; echo "scripts_smoke: device_check with no budget ran a stage" >&2; exit 1; }
  # The full-scale Table 6 from the loop's parameters, here the tiny specimen at one pressure; the loop's calibrated.csv
  # stands in as Table 5's S-1 values, S-2 has none (a row that says so).
  mkdir -p "$work/t6loop/S-1_all/calibrate_x"
  printf 'material,parameter,value,low95,high95\nS-1,mu_s,0.15,0.1,0.2\nS-1,mu_r,0.015,0,0.05\n' \
    > "$work/t6loop/S-1_all/calibrate_x/calibrated.csv"
  check "perf/device_check.sh table6" env TINY=1 BUILD="$build" MATERIALS="S-1 S-2" PRESSURES=100 \
    bash "$root/perf/device_check.sh" table6 "$work/t6loop" "$work/t6"
  grep -q '^| S-1 | 100 | 142.4 | [0-9.]* | .* | mu_s 0.15; mu_r 0.015 | .* | done |' "$work/t6/table6.md" &&
    grep -q '^| S-2 | 100 | .* | not calibrated |' "$work/t6/table6.md" ||
    { cat "$work/t6/table6.md"; echo "scripts_smoke: device_check table6 gave no row per case" >&2; exit 1; }
  # The peers' packing format and the instruction count, on a 216-ball packing, triaxdem alone (the peers are
  # Debian packages the CI does not install).
  sed -e 's/^count = .*/count = 216/' -e 's/^size_mm = .*/size_mm = [11.94, 11.94, 11.94]/' \
      "$root/perf/configs/periodic_54k.toml" > "$work/packing.toml"
  check perf/peer_benchmark.sh env BUILD="$build" WORK="$work/peers" CONFIG="$work/packing.toml" PEERS= STEPS=20 REPS=1 \
    NP=1 CSV="$work/peers.csv" bash "$root/perf/peer_benchmark.sh"
  exists "$work/peers/packing.data"
  grep -Eq "^[0-9]{4}-[0-9]{2}-[0-9]{2},[0-9a-f+]+,[^,]+,1,216,20,triaxdem,[0-9.e+]+," "$work/peers.csv" ||
    { cat "$work/peers.csv"; echo "scripts_smoke: peer_benchmark wrote no CSV row" >&2; exit 1; }
  # Valgrind (Debian 12's 3.19) cannot decode AVX-512: on a machine whose build chose x86-64-v4 the script must say
  # so and stop, which is this tiny case's outcome there.
  echo "== perf/instruction_count.sh"
  # BYTES=1: the cache simulation too (its bytes column; zero or more on a packing this small).
  if BUILD="$build" WORK="$work/peers" CONFIG="$work/packing.toml" PEERS= N1=2 N2=4 BYTES=1 \
       bash "$root/perf/instruction_count.sh" > "$work/instructions.log" 2>&1; then
    awk '$1 == "triaxdem" && $2 > 0 && NF == 3 { found = 1 } END { exit !found }' "$work/instructions.log" ||
      { cat "$work/instructions.log"; echo "scripts_smoke: no instruction count" >&2; exit 1; }
  elif ! grep -q "valgrind cannot run triaxdem's AVX-512 code" "$work/instructions.log"; then
    cat "$work/instructions.log"; echo "scripts_smoke: perf/instruction_count.sh failed" >&2; exit 1
  fi
  ran+=(perf/instruction_count.sh)
  check perf/specimen_scatter.sh env BUILD="$build" WORK="$work/scatter" SEEDS=2 FACTORS="1 2" \
    bash "$root/perf/specimen_scatter.sh"
  check tools/specimen_scatter.py "$py" "$root/tools/specimen_scatter.py" "$work/scatter"
  check perf/bench_engine "$build/perf/bench_engine" --benchmark_filter='BM_TimeLoop/12/1|BM_CellBatch/4/5' \
    --benchmark_min_time=0.01
fi

# The diagnoses (the second part).
if [ "$part" != tools ]; then
  check perf/stage_profile.sh env BUILD="$build" WORK="$work/profile" CONFIG="$root/tests/data/tiny_triaxial.toml" \
    DIAG_CONFIG="$base" PRESSURES=100 BENCH_STEPS=20 NP=1 bash "$root/perf/stage_profile.sh"
  grep -q "^shear .* | " "$work/stage_profile.sh.log" && grep -q "^diagnose: .* runs" "$work/stage_profile.sh.log" ||
    { cat "$work/stage_profile.sh.log"; echo "scripts_smoke: stage_profile gave no shear stage or no diagnosis" >&2; exit 1; }
  # The sweep through the identification table's script (one null case; the data on a cell of the simulator's size:
  # the generator's larger cell is the sweep's default, not what this checks), then the script again: nothing left.
  check perf/identification_table.sh env BUILD="$build" OUT="$work/ident" LEVELS=precise HIDDEN_SEEDS= NULL_SEEDS=1 \
    JOBS=1 SWEEP_ARGS="--config $base --data-cell-factor 1" bash "$root/perf/identification_table.sh"
  ran+=(perf/hidden_sweep)
  grep -q "^none,0,1,none,.*,[0-9]*$" "$work/ident/precise.csv" && grep -q "^- false alarms: \*\*0 of 1\*\*" \
    "$work/identification_table.sh.log" ||
    { cat "$work/identification_table.sh.log"; echo "scripts_smoke: identification_table gave no null row" >&2; exit 1; }
  # Each row names the best generic discrepancy, every extension's rival, with its BIC gain and held-out chi2.
  grep -Eq "^none,0,1,.*,[a-z_ ]+,[-0-9.]+,[-0-9.a-z]+,[^,]+,[0-9]+$" "$work/ident/precise.csv" ||
    { cat "$work/ident/precise.csv"; echo "scripts_smoke: identification_table's row names no rival" >&2; exit 1; }
  env BUILD="$build" OUT="$work/ident" LEVELS=precise HIDDEN_SEEDS= NULL_SEEDS=1 bash "$root/perf/identification_table.sh" \
    > "$work/ident_again.log"
  grep -q " 0 cases left" "$work/ident_again.log" || { echo "scripts_smoke: identification_table ran a case it had" >&2; exit 1; }
  # Table 6 by the loop: each case's plan (a case runs 30-60 minutes), then the table, whose rows say "not run".
  check perf/table6_loop.sh env BUILD="$build" WORK="$work/table6" MATERIALS=S-1 CASES="all 300" JOBS=1 PLAN=1 \
    bash "$root/perf/table6_loop.sh"
  [ "$(grep -c '^| S-1 | .* | not run |' "$work/table6_loop.sh.log")" = 2 ] ||
    { cat "$work/table6_loop.sh.log"; echo "scripts_smoke: table6_loop gave no row per case" >&2; exit 1; }
  # A case done before is kept (KEEP) with its files and run.csv, and run no more: the committed S-1 case stands in.
  mkdir -p "$work/table6/S-1_all/calibrate_x" && echo 4470 > "$work/table6/S-1_all.seconds" &&
    cp "$root/data/results/table6_loop/S-1_all/prediction.csv" "$root/data/results/table6_loop/S-1_all/calibrated.csv" \
      "$work/table6/S-1_all/calibrate_x/"
  BUILD="$build" WORK="$work/table6" MATERIALS=S-1 CASES=all KEEP="$work/kept" bash "$root/perf/table6_loop.sh" \
    > "$work/table6_keep.log" 2>&1 && grep -q "done before, kept" "$work/table6_keep.log" &&
    [ "$(tail -1 "$work/kept/S-1_all/run.csv" | cut -d, -f1,2)" = "perf/table6_loop.sh S-1_all,4470" ] &&
    cmp -s "$work/kept/S-1_all/prediction.csv" "$root/data/results/table6_loop/S-1_all/prediction.csv" ||
    { cat "$work/table6_keep.log"; echo "scripts_smoke: table6_loop did not keep a case done before" >&2; exit 1; }
  # The coverage study on one tiny case (the tiny base, data of the cell's size), then again: the case is not run twice;
  # its row holds the truth, the intervals, the region's rise and the truth's own run.
  check perf/coverage.sh env BUILD="$build" BASE="$base" OUT="$work/coverage" WORK="$work/coverage_runs" CASES=1 SIZES=1 \
    JOBS=1 METHOD=tiny bash "$root/perf/coverage.sh"
  grep -Eq "^tiny,[0-9a-f+]+,1,1,0\.[0-9]+,0\.[0-9]+(,[-0-9.e]+){6},[0-9.e]+,[0-9.]+,[0-9]+,[0-9.]+,[0-9]+,[0-9]+,[01],[01]$" \
    "$work/coverage/tiny.csv" && grep -q "^| tiny | 1x the cell's balls | 1 | " "$work/coverage.sh.log" ||
    { cat "$work/coverage/tiny.csv" "$work/coverage.sh.log"; echo "scripts_smoke: coverage wrote no case row" >&2; exit 1; }
  env BUILD="$build" BASE="$base" OUT="$work/coverage" WORK="$work/coverage_runs" CASES=1 SIZES=1 METHOD=tiny \
    bash "$root/perf/coverage.sh" > "$work/coverage_again.log"
  grep -q ": 0 to run," "$work/coverage_again.log" && [ "$(wc -l < "$work/coverage/tiny.csv")" = 2 ] ||
    { cat "$work/coverage_again.log"; echo "scripts_smoke: coverage ran a case it had" >&2; exit 1; }
  # The same case analysed again from its runs (REUSE): a row of its own, from the earlier case's data and runs.
  env BUILD="$build" BASE="$base" OUT="$work/coverage" WORK="$work/coverage_runs" CASES=1 SIZES=1 METHOD=tiny_again \
    REUSE=tiny JOBS=1 bash "$root/perf/coverage.sh" > "$work/coverage_reuse.log" 2>&1 &&
    grep -q "^tiny_again,[0-9a-f+]*,1,1,$(cut -d, -f5,6 <<< "$(sed -n 2p "$work/coverage/tiny.csv")")," \
      "$work/coverage/tiny_again.csv" && cmp -s "$work/coverage_runs/tiny_1x/case1/data.csv" \
      "$work/coverage_runs/tiny_again_1x/case1/data.csv" ||
    { cat "$work/coverage_reuse.log"; echo "scripts_smoke: coverage's REUSE gave no row from the case's data" >&2; exit 1; }
  ran+=(tools/coverage_table.py)
  # A folder the script did not make is never removed: refused, its file kept.
  mkdir -p "$work/coverage_user/tiny_1x/case2" && touch "$work/coverage_user/tiny_1x/case2/keep"
  ! env BUILD="$build" BASE="$base" OUT="$work/coverage" WORK="$work/coverage_user" FIRST=2 CASES=1 SIZES=1 METHOD=tiny \
    bash "$root/perf/coverage.sh" > "$work/coverage_user.log" 2>&1 && [ -f "$work/coverage_user/tiny_1x/case2/keep" ] &&
    grep -q "holds files this script did not make" "$work/coverage_user.log" ||
    { cat "$work/coverage_user.log"; echo "scripts_smoke: coverage removed a folder it did not make" >&2; exit 1; }
  # The tutorial's commands (docs/tutorial.md) on their tiny cell: a calibration and a diagnosis, each with its report.
  check scripts/tutorial.sh env BUILD="$build" JOBS=1 TINY=1 bash "$root/scripts/tutorial.sh" "$work/tutorial"
  exists "$(ls -d "$work"/tutorial/calibrate/calibrate_*)/calibrated.csv" \
    "$(ls -d "$work"/tutorial/diagnose/diagnose_*)/diagnosis.md"
  check perf/inertial_scan "$build/perf/inertial_scan" --config "$base" --specimens 2 --pressures 100 \
    --inertial 1e-3,4e-3 -j 1 -o "$work/inertial.csv"
  exists "$work/inertial.csv"
  check perf/inertial_scan_preparation "$build/perf/inertial_scan" --config "$base" --specimens 2 --pressures 100 \
    --preparation-emod 1e8,2e8 -j 1 -o "$work/preparation.csv"
  grep -q "^2e+08,100,q,0," "$work/preparation.csv" ||
    { cat "$work/preparation.csv"; echo "scripts_smoke: the preparation scan has no peak row" >&2; exit 1; }
fi

# Every script and perf program has its line above, in one part or the other.
missing=""
for f in "$root"/perf/*.sh "$root"/perf/*.cpp "$root"/tools/*.py; do
  [[ "$(basename "$f")" == _* ]] && continue  # a module the tools import, not a script
  name="$(basename "$(dirname "$f")")/$(basename "$f")"; name="${name%.cpp}"
  grep -Eq "^ *(check $name |ran\+=\($name\))" "${BASH_SOURCE[0]}" || missing+=" $name"
done
[ -z "$missing" ] || { echo "scripts_smoke: no tiny case for:$missing (add one to tests/scripts_smoke.sh)" >&2; exit 1; }
echo "scripts_smoke ($part): ${#ran[@]} scripts ran on tiny cases"
