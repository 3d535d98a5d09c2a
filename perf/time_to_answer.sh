#!/usr/bin/env bash
# Time to an answer: each case's plan (what the job says before it starts), then the job from a clean output folder,
# then the same job again on the same base (its packings read from the packing store), with each one's wall time,
# runs, packing time and the plan beside it, as a Markdown table (docs/performance.md, Time to an answer).
#   perf/time_to_answer.sh                      # CASES="walled s1_two_fidelity" JOBS=2 BUILD=build
#                                               # WORK=runs/time_to_answer SECOND=1 STORE=
# STORE: an output folder of an earlier job on the same base whose packing store (.specimens) each case starts from
# (the scripts' check reuses its own tiny calibration's; a measurement leaves it empty: clean output folders).
# A case is a name below (a calibrate or diagnose command line) or "tiny" (the scripts' check: a synthetic curve on
# the hidden-effect base, 1% strain). walled: YADE's walled data on the walled base (about 6 minutes on 2 cores);
# s1_two_fidelity: Table 6's S-1 with two fidelities, ensemble 4 (about 25 minutes); diagnosis: a default diagnosis
# of YADE's linear curves on the cross-code base. Issue 61's goals at the sizes it names: walled_4000, the walled
# calibration with the walled base grown to 4,000 balls (its box by the cube root; the data's curves as shipped,
# taken to be of the cell's size); diagnosis_800, the default diagnosis on the cross-code base grown to 800 balls.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
. "$root/scripts/script_folders.sh"
build="$(build_folder time_to_answer)"; work="$(realpath -m "${WORK:-$root/runs/time_to_answer}")"
cases="${CASES:-walled s1_two_fidelity}"; jobs="${JOBS:-2}"; second="${SECOND:-1}"; store="${STORE:-}"
tdem="$build/triaxdem"
[ -x "$tdem" ] || { echo "time_to_answer: build triaxdem first ($tdem)"; exit 1; }
export OMP_NUM_THREADS=1  # -j runs at once, one thread each
cd "$root"
grown() {  # CONFIG BALLS: the config with BALLS balls, its box grown by the cube root of the ratio (the same density)
  python3 - "$1" "$2" <<'PY'
import re, sys
text, balls = open(sys.argv[1]).read(), int(sys.argv[2])
old = int(re.search(r'^count = (\d+)', text, re.M).group(1))
f = (balls / old) ** (1 / 3)
text = re.sub(r'^count = \d+', 'count = %d' % balls, text, count=1, flags=re.M)
text = re.sub(r'^size_mm = \[([^]]*)\]', lambda m: 'size_mm = [%s]' % ', '.join(
    '%.4g' % (float(x) * f) for x in m.group(1).split(',')), text, count=1, flags=re.M)
print(text, end='')
PY
}
args_of() {  # CASE: the job's command line
  case "$1" in
    tiny)
      sed -e 's/^ensemble = .*/ensemble = 1/' -e 's/^scatter_specimens = .*/scatter_specimens = 2/' \
          -e 's/^target_axial_strain_pct = .*/target_axial_strain_pct = 1.0/' tests/data/hidden_effects.toml \
          > "$work/tiny.toml"
      "$tdem" synth --config "$work/tiny.toml" -o "$work/tiny.csv" --extension none --seed 1 --pressures 100 \
          > "$work/tiny_synth.log" 2>&1
      echo "calibrate $work/tiny.csv --config $work/tiny.toml --predict none" ;;
    walled)
      echo "calibrate tests/data/crosscode/walled_seed1.csv --config tests/data/crosscode/walled_base.toml" ;;
    s1_two_fidelity)
      { cat configs/calibration/base.toml; printf 'ensemble = 4\nscatter_specimens = 4\nreference_test = "two_fidelity"\n'; } \
          > "$work/s1_base.toml"
      echo "calibrate data/tang2025_table6_peak.csv --config $work/s1_base.toml --predict configs/small/S1_100kPa.toml --material S-1" ;;
    diagnosis)
      echo "diagnose tests/data/crosscode/linear_seed1.csv --config tests/data/crosscode/linear_base.toml --predict none" ;;
    walled_4000)
      grown tests/data/crosscode/walled_base.toml 4000 > "$work/walled_4000.toml"
      echo "calibrate tests/data/crosscode/walled_seed1.csv --config $work/walled_4000.toml" ;;
    diagnosis_800)
      grown tests/data/crosscode/linear_base.toml 800 > "$work/linear_800.toml"
      echo "diagnose tests/data/crosscode/linear_seed1.csv --config $work/linear_800.toml --predict none" ;;
  esac
}
field() {  # LOG PATTERN: the first group of the first line that matches (sed -E)
  sed -nE "s/.*$2.*/\1/p" "$1" | head -1
}
# The cases are checked before the folder is touched (a case misspelt once cost the folder its files).
known="tiny walled s1_two_fidelity diagnosis walled_4000 diagnosis_800"
for c in $cases; do
  [[ " $known " == *" $c "* ]] || { echo "time_to_answer: no case '$c' (${known// /, }); nothing was run or removed" >&2; exit 2; }
done
fresh_folder time_to_answer "$work"
echo "| case | plan | job | of it packing | simulator runs | plan beside it |"
echo "|---|---|---|---|---|---|"
for c in $cases; do
  args="$(args_of "$c")"
  if [ -n "$store" ]; then mkdir -p "$work/$c" && cp -r "$store/.specimens" "$work/$c/"; fi
  # shellcheck disable=SC2086
  "$tdem" $args -j "$jobs" --plan -o "$work/$c" > "$work/${c}_plan.log" 2>&1
  plan="$(field "$work/${c}_plan.log" ': in all .* about (.*) on this machine')"
  for pass in first second; do
    [ "$pass" = second ] && [ "$second" != 1 ] && continue
    log="$work/${c}_$pass.log"
    # shellcheck disable=SC2086
    "$tdem" $args -j "$jobs" -o "$work/$c" > "$log" 2>&1 || { tail -20 "$log"; echo "time_to_answer: $c failed" >&2; exit 1; }
    job="$(field "$log" "the job's ([0-9hms]+):")"
    packing="$(field "$log" 'packing specimens ([0-9hms]+)')"
    runs="$(field "$log" "the job's [0-9hms]+: ([0-9]+) simulator runs")"
    said="$(field "$log" 'the plan said about (.*); the job took')"
    echo "| $c ($pass) | $plan | $job | $packing | $runs | $said |"
  done
done
