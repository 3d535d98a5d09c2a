#!/bin/bash
# Regenerates the YADE cross-code triaxial curves in this folder (single-threaded, niced).
# Usage: tests/data/crosscode/make_crosscode_data.sh [file-stem ...]   (default: all six)
#   stems: linear_seed1 hertz_seed1 linear_seed2 hertz_seed2 walled_seed1 walled_seed2 walled4k_seed1;   logs go to /tmp/crosscode_<stem>.log
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
if ! command -v yade >/dev/null 2>&1; then
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends yade
fi
ver="$(yade --version 2>/dev/null | grep -i 'yade version' | head -1 | sed 's/^ *//;s/ *$//'); dpkg $(dpkg-query -W -f='${Package} ${Version}' yade)"
run() {  # stem law seed balls pressures material [script]
  local stem=$1 log=/tmp/crosscode_$1.log t0=$SECONDS script=${7:-yade_peri_triax.py}
  echo "$(date '+%F %T') $stem ..."
  (cd /tmp && nice -n 10 yade -j1 -n -x "$here/$script" law=$2 seed=$3 n=$4 pressures=$5 mat=$6 \
      "out=$here/$stem.csv" "version=$ver") >"$log" 2>&1 || { echo "$stem FAILED, see $log:" >&2; tail -5 "$log" >&2; exit 1; }
  echo "$(date '+%F %T') $stem done in $((SECONDS - t0)) s ($(grep -vc '^#' "$here/$stem.csv") lines)"
}
stems=("$@"); [ ${#stems[@]} -eq 0 ] && stems=(linear_seed1 hertz_seed1 linear_seed2 hertz_seed2 walled_seed1 walled_seed2)
for s in "${stems[@]}"; do
  case $s in
    linear_seed1) run $s linear 1 1500 60,150,300  lin ;;
    hertz_seed1)  run $s hertz  1 1000 100,200,400 hz ;;
    linear_seed2) run $s linear 2 1500 80,200,350  lin ;;
    hertz_seed2)  run $s hertz  2 1000 100,250,400 hz ;;
    walled_seed1) run $s linear 1 1000 100,200,300 wall yade_walled_triax.py ;;
    walled_seed2) run $s linear 2 1000 80,150,250  wall yade_walled_triax.py ;;
    walled4k_seed1) run $s linear 1 4000 100,200,300 wall yade_walled_triax.py ;;
    *) echo "unknown stem $s" >&2; exit 2 ;;
  esac
done
