#!/usr/bin/env bash
# The tutorial's commands (docs/tutorial.md), in its order: a lab's peak strengths (Table 6's S-1) calibrated on the
# shipped quick calibration cell, then curves with an effect hidden in them diagnosed on the cheap cell of the
# hidden-effect tests. About 13 minutes on 2 cores (each job prints its plan first). TINY=1 runs every step on a cell
# cut to seconds, on synthetic data in place of the lab's: the scripts' smoke test runs it so, so that the page
# cannot rot.
#   bash scripts/tutorial.sh [OUT]                 # default out/tutorial; BUILD=path/to/build, JOBS=2
#   TINY=1 bash scripts/tutorial.sh OUT
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${BUILD:-$root/build}"
tdem="$build/triaxdem"
[ -x "$tdem" ] || { echo "tutorial: no program at $tdem: build it first, or name its build folder with BUILD=" >&2; exit 2; }
out="${1:-out/tutorial}"
jobs="${JOBS:-2}"
mkdir -p "$out"
step() { printf '\n== tutorial: %s\n' "$*"; }

if [ "${TINY:-0}" = 1 ]; then
  calib="$out/tiny_cell.toml"
  sed -e 's/^ensemble = .*/ensemble = 1/' -e 's/^scatter_specimens = .*/scatter_specimens = 2/' \
      -e 's/^target_axial_strain_pct = .*/target_axial_strain_pct = 1.0/' "$root/tests/data/hidden_effects.toml" > "$calib"
  diag="$calib"
  lab="$out/lab.csv"
  "$tdem" synth --config "$calib" -o "$lab" --overwrite --extension none --seed 1 --pressures 100 200 --material S-1
  pressures=(100 200)
else
  calib="$root/configs/calibration/quick.toml"
  diag="$root/tests/data/hidden_effects.toml"
  lab="$root/data/tang2025_table6_peak.csv"
  pressures=(100 200 300)
fi

step "1. the cell the calibration runs: checked and described"
"$tdem" check "$calib"
step "2. what the calibration will cost, before any work"
"$tdem" calibrate "$lab" --config "$calib" --material S-1 --predict none -j "$jobs" -o "$out/calibrate" --plan
step "3. the calibration of S-1's peak strengths"
"$tdem" calibrate "$lab" --config "$calib" --material S-1 --predict none -j "$jobs" -o "$out/calibrate"
step "4. curves with Hertz-Mindlin contacts hidden in them"
"$tdem" synth --config "$diag" -o "$out/hidden.csv" --overwrite --extension hertz --strength 3e-3 --seed 1 \
  --pressures "${pressures[@]}" --material hidden
step "5. the diagnosis: what the linear model gets wrong, and which extension explains it"
"$tdem" diagnose "$out/hidden.csv" --config "$diag" --predict none -j "$jobs" -o "$out/diagnose"
cal="$(ls -d "$out"/calibrate/calibrate_* | tail -n 1)"
dia="$(ls -d "$out"/diagnose/diagnose_* | tail -n 1)"
echo
echo "tutorial: the calibration in $cal (calibrated.csv, errors.csv, calibration.png), the diagnosis in $dia"
echo "tutorial: (diagnosis.md, models.csv, calibration.png); docs/tutorial.md says how to read each"
