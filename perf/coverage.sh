#!/usr/bin/env bash
# Coverage of the calibration's 95% intervals (issue 85): synthetic data sets made by `triaxdem synth` at (mu_s, mu_r)
# drawn across the searched box, each calibrated from BASE as a user would (its settings, --predict none) with the
# generating values given as --reference, and whether each 95% interval and the joint 95% region hold them. The case
# number seeds the draw, the data's noise and the data's specimens (packing seeds 300000 + 10 x case above the base's:
# no calibration packs them). SIZES: the data specimens' balls as a multiple of the cell's (synth --cell-factor),
# reported apart. One row a case and size in OUT/<METHOD>.csv with its commit and seconds; a case already there is not
# run again, so the study fills over several sittings, each started only where BUDGET seconds leave its time (CASE_S
# until the rows give their own mean). Then tools/coverage_table.py's table. PLAN=1 prints the plan and the table only.
#   perf/coverage.sh   # CASES=30 FIRST=1 SIZES="1 4" BASE=tests/data/hidden_effects.toml METHOD=ensemble JOBS=2
#                      # BUDGET=3600 CASE_S=300 BUILD=build OUT=data/sweeps/coverage WORK=runs/coverage PLAN=0
#                      # MU_S="0.06 0.40" (log-uniform) MU_R="0.005 0.055" (uniform) CAL_ARGS= (more calibrate options)
#                      # STATE=1 (0: the data's void_ratio column dropped, so that the cells keep the base's preparation,
#                      # the data's own: what matching the cells to one data set's void ratio costs the intervals)
#                      # SEARCH=ensemble ([calibrate] method of the calibrations: ensemble or one_specimen; BASE's copy
#                      # in WORK carries it)
#                      # REUSE= (an earlier METHOD whose case folders in WORK are analysed again: their data and runs
#                      # copied and the calibration resumed, so that only points the new code asks for run; the same
#                      # data and specimens, what a change to the intervals alone does, case by case)
# WORK holds each case's data and calibration folder; the script removes only case folders it made (a marker file:
# scripts/script_folders.sh).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
. "$root/scripts/script_folders.sh"
fail() { echo "coverage: $*" >&2; exit 2; }
whole() { [[ "$2" =~ ^[0-9]+$ ]] || fail "$1=$2: a whole number"; }
cases="${CASES:-30}"; first="${FIRST:-1}"; sizes="${SIZES:-1 4}"; jobs="${JOBS:-2}"; budget="${BUDGET:-3600}"
case_s="${CASE_S:-300}"; plan="${PLAN:-0}"; state="${STATE:-1}"; method="${METHOD:-ensemble}"; cal_args="${CAL_ARGS:-}"
search="${SEARCH:-ensemble}"; reuse="${REUSE:-}"
mu_s_box="${MU_S:-0.06 0.40}"; mu_r_box="${MU_R:-0.005 0.055}"
for v in cases first jobs budget case_s; do whole "${v^^}" "${!v}"; done
for s in $sizes; do whole SIZES "$s"; [ "$s" -ge 1 ] && [ "$s" -le 64 ] || fail "SIZES: $s is not in 1..64"; done
[[ "$state" =~ ^[01]$ ]] || fail "STATE=$state: 1 (the data's void ratio matched) or 0 (dropped)"
[[ "$method" =~ ^[A-Za-z0-9_-]+$ ]] || fail "METHOD=$method: letters, digits, _ and - only (it names OUT/<METHOD>.csv)"
[[ "$search" =~ ^(ensemble|one_specimen)$ ]] || fail "SEARCH=$search: ensemble or one_specimen"
[[ "$reuse" =~ ^[A-Za-z0-9_-]*$ ]] || fail "REUSE=$reuse: letters, digits, _ and - only (an earlier METHOD)"
[ "$reuse" != "$method" ] || [ -z "$reuse" ] || fail "REUSE=$reuse: the METHOD itself; name the new rows otherwise"
build="$(build_folder coverage)"; tdem="$build/triaxdem"
[ -x "$tdem" ] || fail "no triaxdem in BUILD=$build (build it first: cmake --build $build --target triaxdem)"
base="$(realpath "${BASE:-$root/tests/data/hidden_effects.toml}")"
[ -f "$base" ] || fail "BASE=$base: no such config"
out="$(realpath -m "${OUT:-$root/data/sweeps/coverage}")"; work="$(realpath -m "${WORK:-$root/runs/coverage}")"
py=python3; [ -x /usr/bin/python3 ] && py=/usr/bin/python3
commit="$(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo unknown)"
git -C "$root" diff --quiet HEAD -- host kernels perf 2>/dev/null || commit="$commit+"  # uncommitted code changes
csv="$out/$method.csv"
header="method,commit,case,size,mu_s_true,mu_r_true,mu_s,mu_s_lo,mu_s_hi,mu_r,mu_r_lo,mu_r_hi,region_rise,chi2,data,truth_chi2,runs,seconds,finding,edge"
mkdir -p "$out" "$work"
if [ "$search" != ensemble ]; then  # the calibrations' base: BASE with [calibrate] method set
  grep -q '^\[calibrate\]' "$base" || fail "BASE=$base: no [calibrate] table to set method in"
  ! grep -q '^method *=' "$base" || fail "BASE=$base: sets method itself; SEARCH would be ignored"
  sed "s/^\[calibrate\]/[calibrate]\nmethod = \"$search\"/" "$base" > "$work/base_$search.toml"
  base="$work/base_$search.toml"
fi
[ -f "$csv" ] || echo "$header" > "$csv"
[ "$(head -1 "$csv")" = "$header" ] || fail "$csv has other columns than this script writes: move it aside"
export OMP_NUM_THREADS=1  # -j runs at once, one thread each

have() { awk -F, -v c="$1" -v s="$2" 'NR > 1 && $3 == c && $4 == s' "$csv" | grep -q .; }
# SIZE: a case's seconds, the mean of this method's rows of that size, else of REUSE's (whose runs a case reads: an
# upper bound, about 1.5 times what 30 such cases took), else of every method's in OUT (the same cells and searches),
# else CASE_S.
mean_case() {
  awk -F, -v d="$case_s" -v z="$1" -v m="$method" -v r="$reuse" 'FNR > 1 && $4 == z && $18 > 0 {
      if ($1 == m) { s += $18; n++ } else if ($1 == r) { u += $18; j++ } else { o += $18; k++ } }
    END { printf "%d", n ? s / n : j ? u / j : k ? o / k : d }' "$out"/*.csv
}
plan_s() { local t=0 i; for i in "$@"; do t=$((t + $(mean_case "${i##*:}"))); done; echo "$t"; }
truth() {  # CASE: "mu_s mu_r", drawn from the case number (the same on every machine)
  "$py" -c 'import math, random, sys
r = random.Random(int(sys.argv[1])); a, b = map(float, sys.argv[2].split()); c, d = map(float, sys.argv[3].split())
print("%.4g %.4g" % (math.exp(math.log(a) + r.random() * math.log(b / a)), c + r.random() * (d - c)))' \
    "$1" "$mu_s_box" "$mu_r_box"
}
todo=()
for ((c = first; c < first + cases; c++)); do for s in $sizes; do have "$c" "$s" || todo+=("$c:$s"); done; done
total="$(plan_s "${todo[@]}")"
echo "coverage: $method, cases $first..$((first + cases - 1)), data sizes ${sizes// /x, }x the cell's: ${#todo[@]} to run," \
     "${reuse:+at most (the runs read from $reuse), }about $(( total / 60 )) min in all on this machine (-j $jobs; each case as the rows of its size took); this sitting's budget" \
     "$budget s"
if [ "$plan" != 1 ]; then
  start=$SECONDS; done_here=0
  for item in "${todo[@]}"; do
    c="${item%%:*}"; s="${item##*:}"
    elapsed=$((SECONDS - start)); each="$(mean_case "$s")"
    if [ $((elapsed + each)) -gt "$budget" ]; then
      echo "coverage: budget reached after $done_here cases ($elapsed s); run again to go on"; break
    fi
    read -r mu_s mu_r <<< "$(truth "$c")"
    dir="$work/${method}_${s}x/case$c"
    fresh_folder coverage "$dir"
    left="$(plan_s "${todo[@]:done_here}")"
    echo "coverage: case $c, data of ${s}x the cell's balls, mu_s $mu_s, mu_r $mu_r ($((done_here + 1)) of" \
         "${#todo[@]}; about $((left / 60)) min left)"
    sed -e "s/^mu_s = .*/mu_s = $mu_s/" -e "s/^mu_r = .*/mu_r = $mu_r/" "$base" > "$dir/truth.toml"
    grep -q "^mu_s = $mu_s\$" "$dir/truth.toml" && grep -q "^mu_r = $mu_r\$" "$dir/truth.toml" ||
      fail "BASE=$base: no [material] mu_s and mu_r lines to set the truth in"
    printf 'material,mu_s,mu_r\nsynthetic,%s,%s\n' "$mu_s" "$mu_r" > "$dir/truth.csv"
    t0=$SECONDS
    earlier="$work/${reuse}_${s}x/case$c"; resume=()
    if [ -n "$reuse" ]; then
      [ -f "$earlier/data.csv" ] && ls -d "$earlier"/cal/calibrate_* > /dev/null 2>&1 ||
        fail "REUSE=$reuse: no data and calibration of case $c in $earlier"
      cp "$earlier/data.csv" "$dir/"; cp -r "$earlier/cal" "$dir/cal"
      resume=(--resume "$(ls -d "$dir"/cal/calibrate_* | head -1)")
    fi
    seed="$(sed -n 's/^seed = \([0-9]*\).*/\1/p' "$base" | head -1)"
    [ -n "$reuse" ] || "$tdem" synth --config "$dir/truth.toml" -o "$dir/data.csv" --extension none --seed "$((1000 + c))" \
      --specimen-seed "$((${seed:-1} + 300000 + 10 * c))" --cell-factor "$s" > "$dir/synth.log" 2>&1 ||
      { tail -5 "$dir/synth.log"; fail "case $c: synth failed ($dir/synth.log)"; }
    if [ "$state" = 0 ]; then
      "$py" - "$dir/data.csv" <<'PY'
import csv, sys
lines = open(sys.argv[1]).read().splitlines(True)
head = [l for l in lines if l.startswith("#")]
rows = list(csv.reader([l for l in lines if not l.startswith("#")]))
keep = [i for i, c in enumerate(rows[0]) if c != "void_ratio"]
with open(sys.argv[1], "w", newline="") as f:
    f.writelines(head)
    csv.writer(f, lineterminator="\n").writerows([[r[i] for i in keep] for r in rows])
PY
    fi
    # shellcheck disable=SC2086
    "$tdem" calibrate "$dir/data.csv" --config "$base" --reference "$dir/truth.csv" --predict none -j "$jobs" \
      -o "$dir/cal" "${resume[@]}" $cal_args > "$dir/calibrate.log" 2>&1 ||
      { tail -5 "$dir/calibrate.log"; fail "case $c: calibrate failed ($dir/calibrate.log)"; }
    secs=$((SECONDS - t0))
    cal="$(ls "$dir"/cal/calibrate_*/calibrated.csv)"
    finding=0; grep -q 'FINDING' "$dir/calibrate.log" && finding=1
    edge=0; grep -q 'at the edge of its range' "$dir/calibrate.log" && edge=1
    "$py" - "$cal" "$method,$commit,$c,$s,$mu_s,$mu_r" "$secs,$finding,$edge" >> "$csv" <<'PY'
import csv, sys
rows = {r["parameter"]: r for r in csv.DictReader(open(sys.argv[1]))}
s, r = rows["mu_s"], rows["mu_r"]
print(",".join([sys.argv[2], s["value"], s["low95"], s["high95"], r["value"], r["low95"], r["high95"],
                s["reference_rise"], s["chi2"], s["data"], s["reference_chi2"], s["runs"], sys.argv[3]]))
PY
    done_here=$((done_here + 1))
  done
fi
"$py" "$root/tools/coverage_table.py" "$out"
