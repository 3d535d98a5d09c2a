#!/usr/bin/env bash
# Table 6 by the closed loop (issue 62, item 2): each material of the paper's Table 6 calibrated on the periodic cell
# with two fidelities to their fixed point (the small membrane specimen, configs/small/), its three pressures
# predicted by the membrane test; and each pressure held out in turn (fit two, predict the third). One case is one
# `triaxdem calibrate` in WORK/<material>_<all|hold<kPa>>; a case whose folder holds a prediction.csv is not run again,
# so a study too long for one sitting goes on where it stopped. Then the table, one row per case and pressure, from
# the prediction.csv files (Markdown on stdout), with each case's wall time and its calibrated values.
#   perf/table6_loop.sh        # MATERIALS="S-1 S-2 S-3" CASES="all 100 200 300" JOBS=2 BUILD=build
#                              # WORK=runs/table6_loop ENSEMBLE=4 PLAN=0 KEEP=
# KEEP=DIR (the results page's is data/results/table6_loop): each case done, now or before, is kept there as
# DIR/<case>/prediction.csv, calibrated.csv and run.csv (the command, its seconds, the commit, the machine, the date).
# On 2 cores a case takes about 30-60 minutes (the plan of each says so before it runs); PLAN=1 prints each case's
# plan and runs nothing, then the table of what is done (the scripts' check).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
. "$root/scripts/script_folders.sh"
build="$(build_folder table6_loop)"; work="$(realpath -m "${WORK:-$root/runs/table6_loop}")"
materials="${MATERIALS:-S-1 S-2 S-3}"; cases="${CASES:-all 100 200 300}"; jobs="${JOBS:-2}"
ensemble="${ENSEMBLE:-4}"; plan="${PLAN:-0}"; keep="${KEEP:-}"
tdem="$build/triaxdem"
[ -x "$tdem" ] || { echo "table6_loop: build triaxdem first ($tdem)"; exit 1; }
mkdir -p "$work"
export OMP_NUM_THREADS=1  # -j runs at once, one thread each
cd "$root"
# The shipped calibration base with two fidelities, a fixed ensemble (the search's cost known in advance) and each
# material's small membrane test as its prediction.
base() {  # MATERIAL: the base config for it
  local m="${1//-/}"
  { sed -e '/^ensemble = /d' -e '/^scatter_specimens = /d' -e '/^reference_test = /d' -e '/^predict = /d' \
      configs/calibration/base.toml
    printf 'ensemble = %s\nscatter_specimens = %s\nreference_test = "two_fidelity"\npredict = "%s"\n' \
      "$ensemble" "$ensemble" "$root/configs/small/${m}_100kPa.toml"; } > "$work/base_$m.toml"
  echo "$work/base_$m.toml"
}
. "$root/scripts/provenance.sh"
keep_case() {  # OUT: a finished case's files into KEEP, with the run's provenance (its commit: the binary's, which
  [ -n "$keep" ] || return 0  # --version names); a case kept before keeps its first record
  local name folder
  name="$(basename "$1")"; folder="$(ls -d "$1"/calibrate_*/ | tail -1)"
  [ -f "$keep/$name/run.csv" ] && return 0
  mkdir -p "$keep/$name"
  cp "$folder/prediction.csv" "$folder/calibrated.csv" "$keep/$name/"
  IFS=, read -r day commit machine <<< "$(provenance_fields "$root")"
  built="$("$tdem" --version | sed -n 's/^triaxdem [^+]*+\([0-9a-f]\{7\}\).*/\1/p')"
  commit="${built:-$commit}"
  printf 'command,seconds,commit,machine,date\nperf/table6_loop.sh %s,%s,%s,%s,%s\n' "$name" \
    "$(cat "$1.seconds" 2>/dev/null || echo 0)" "$commit" "$machine" "$day" > "$keep/$name/run.csv"
}
for m in $materials; do
  cfg="$(base "$m")"
  for c in $cases; do
    out="$work/${m}_$( [ "$c" = all ] && echo all || echo "hold$c")"
    hold=(); [ "$c" = all ] || hold=(--hold-out "$c")
    if [ "$plan" = 1 ]; then
      "$tdem" calibrate data/tang2025_table6_peak.csv --config "$cfg" --material "$m" "${hold[@]}" -j "$jobs" \
          --plan -o "$out" > "$out.plan.log" 2>&1 || { cat "$out.plan.log"; exit 1; }
      grep -E ': in all ' "$out.plan.log" | sed "s|^|$m $c: |"
      continue
    fi
    if ls "$out"/calibrate_*/prediction.csv > /dev/null 2>&1; then
      echo "table6_loop: $m $c: done before, kept"; keep_case "$out"; continue
    fi
    echo "table6_loop: $m $c: running (log $out.log)"
    start=$SECONDS
    "$tdem" calibrate data/tang2025_table6_peak.csv --config "$cfg" --material "$m" "${hold[@]}" -j "$jobs" -o "$out" \
        > "$out.log" 2>&1 || { tail -20 "$out.log"; echo "table6_loop: $m $c failed" >&2; exit 1; }
    echo "$((SECONDS - start))" > "$out.seconds"
    keep_case "$out"
  done
done
# The table: every case's predictions (a case not run yet, as with PLAN=1, is a row that says so), the held-out pressure marked, with the case's rounds, values and time.
python3 - "$work" "$materials" "$cases" <<'PY'
import csv, glob, os, re, sys
work, materials, cases = sys.argv[1], sys.argv[2].split(), sys.argv[3].split()
print("| material | fitted | sigma3 kPa | measured q_peak kPa | predicted kPa | error | calibrated (95% intervals) | rounds | wall time |")
print("|---|---|---|---|---|---|---|---|---|")
for m in materials:
    for c in cases:
        out = os.path.join(work, "%s_%s" % (m, "all" if c == "all" else "hold" + c))
        found = sorted(glob.glob(os.path.join(out, "calibrate_*", "prediction.csv")))
        if not found:
            print("| %s | %s | not run | | | | | | |" % (m, "all" if c == "all" else "all but %s kPa" % c))
            continue
        folder = os.path.dirname(found[-1])
        values = []
        for row in csv.DictReader(open(os.path.join(folder, "calibrated.csv"))):
            values.append("%s %.4g [%.4g, %.4g]" % (row["parameter"], float(row["value"]), float(row["low95"]),
                                                    float(row["high95"])))
        log = open(out + ".log").read() if os.path.exists(out + ".log") else ""
        rounds = re.findall(r"fixed point after (\d+) round", log)
        rounds = rounds[-1] if rounds else ("not converged" if "Not converged" in log else "-")
        chose = re.findall(r"Round (\d+)'s point is the answer", log)
        if chose or "The last optimum stands." in log:
            rounds += "; the membrane test's choice: " + ("round %s's point" % chose[-1] if chose else "the last optimum")
        secs = int(open(out + ".seconds").read()) if os.path.exists(out + ".seconds") else 0
        for row in csv.DictReader(open(found[-1])):
            held = row.get("held_out") == "1"
            print("| %s | %s | %s%s | %s | %.1f +- %.1f | %+.1f%% | %s | %s | %dm%02ds |" % (
                m, "all" if c == "all" else "all but %s kPa" % c, row["sigma3_kPa"], " (held out)" if held else "",
                row["measured_q_peak_kPa"], float(row["predicted_q_peak_kPa"]), float(row["predicted_sd_kPa"]),
                float(row["error_pct"]), "; ".join(values), rounds, secs // 60, secs % 60))
PY
