#!/usr/bin/env bash
# Cost per particle-step against the ball count: the benchmark packing (perf/configs/periodic_54k.toml: a
# jittered cubic array at 0.995 d, periodic, rrlinear, about 6 contacts per ball) at k^3 balls, the cell
# scaled with k, run for STEPS steps on all cores. Prints particle-steps per second, the time per stage
# (binning + contact detection, forces, gather + integration, boundaries) and the peak memory per ball.
#   perf/scaling.sh                 # K="10 22 46 100" (1,000 to 1,000,000 balls) STEPS=300 BUILD=build
# CSV=FILE: one row a size appended (date, commit, machine, threads, the row printed), the results page's file
# (data/results/scaling/scaling.csv).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
. "$root/scripts/script_folders.sh"
. "$root/scripts/provenance.sh"
build="$(build_folder scaling)"; work="$(realpath -m "${WORK:-$root/runs/scaling}")"
steps="${STEPS:-300}"; sizes="${K:-10 22 46 100}"
csv="${CSV:+$(realpath -m "$CSV")}"  # the script may change folder
mkdir -p "$work"
export OMP_NUM_THREADS="${OMP_NUM_THREADS:-$(nproc)}" OMP_PROC_BIND=spread OMP_PLACES=threads
printf "%9s %14s %9s %9s %9s %9s %9s %12s\n" balls "psteps/s" "ns/pstep" rebuild_s forces_s integr_s bound_s "bytes/ball"
for k in $sizes; do
  n=$((k * k * k)); edge=$(awk -v k="$k" 'BEGIN { printf "%.4f", k * 1.99 }')
  cfg="$work/k$k.toml"
  sed -e "s/^count = .*/count = $n/" -e "s/^size_mm = .*/size_mm = [$edge, $edge, $edge]/" \
      -e "s|^output = .*|output = \"$work/out_k$k\"|" "$root/perf/configs/periodic_54k.toml" > "$cfg"
  /usr/bin/time -f "%M" -o "$work/rss_k$k" "$build/triaxdem" run "$cfg" -n "$steps" --overwrite > "$work/log_k$k" 2>&1
  line=$(grep "^time loop:" "$work/log_k$k")
  rate=$(sed -n 's/.*; \([0-9.e+]*\) particle-steps\/s.*/\1/p' <<< "$line")
  stage() { sed -n "s/.*$1 \([0-9.]*\) s.*/\1/p" <<< "$line"; }
  rss_kb=$(tail -1 "$work/rss_k$k")
  row=("$n" "$rate" "$(awk -v r="$rate" 'BEGIN { print 1e9 / r }')" "$(stage rebuild)" "$(stage ball-ball)" \
       "$(stage 'gather+integrate')" "$(stage boundaries)" "$(awk -v m="$rss_kb" -v n="$n" 'BEGIN { print m * 1024 / n }')")
  printf "%9d %14.4g %9.1f %9s %9s %9s %9s %12.0f\n" "${row[@]}"
  if [ -n "$csv" ]; then
    [ -s "$csv" ] || echo "date,commit,machine,threads,steps,balls,psteps_per_s,ns_per_pstep,rebuild_s,forces_s,integrate_s,boundaries_s,bytes_per_ball" > "$csv"
    (IFS=,; echo "$(provenance_fields "$root"),$OMP_NUM_THREADS,$steps,${row[*]}") >> "$csv"
  fi
done
echo "(bytes/ball: the process's peak resident memory over the balls, so it includes the program and, at small N, is dominated by it)"
