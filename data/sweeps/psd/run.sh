#!/bin/bash
# What a wider size distribution does to a periodic cell's void ratio and strength: the calibration base (S-1's
# friction) at 600 balls, with lognormal sizes by mass (D50 2 mm, log_sd 0 to 0.2; 0: the base's equal balls; wider
# needs more balls, the largest ball setting the cell's least size), the box grown with the mean ball volume so that
# every cell starts at the same solid fraction (0.085: random insertion keeps a ball's size until it finds room, and a
# wide distribution's largest balls need it), three packing seeds each, the drained test at 100 kPa to 10%. About
# 7 minutes on one core.
#   BUILD=path/to/build SRC=path/to/repository bash run.sh > psd_width.csv   (from a scratch folder)
set -euo pipefail
B=${BUILD:?set BUILD to the build folder}/triaxdem
BASE=${SRC:?set SRC to the repository}/configs/calibration/base.toml
echo "log_sd,seed,smallest_mm,largest_mm,mean_diameter_mm,void_ratio0,q_peak_kPa,phi_peak_deg,eps_a_peak_pct,max_dilatancy"
for s in 0 0.1 0.2; do
  side=$(python3 -c "import math; print(1.3 * 16.5 * 3 ** (1 / 3) * math.exp(-1.5 * $s * $s))")  # E[d^3] = D50^3 exp(-4.5 s^2)
  for seed in 1 2 3; do
    c=c_${s}_$seed.toml
    if [ "$s" = 0 ]; then psd=""; else psd="psd = \"lognormal\"\nmedian_mm = 2.0\nlog_sd = $s"; fi
    python3 - "$BASE" "$c" "$seed" "$side" "$psd" <<'PY'
import re, sys
base, out, seed, side, psd = sys.argv[1:]
t = open(base).read()
t = re.sub(r"^seed = .*$", "seed = " + seed, t, flags=re.M)
t = re.sub(r"^count = .*$", "count = 600", t, flags=re.M)
t = re.sub(r"^output = .*$", 'output = "' + out[:-5] + '"', t, flags=re.M)
t = re.sub(r"^size_mm = .*$", "size_mm = [%s, %s, %s]" % (side, side, side), t, flags=re.M)
if psd:
    t = re.sub(r"^diameter_mm = .*\n^diameter_ratio = .*$", psd.replace("\\n", "\n"), t, flags=re.M)
open(out, "w").write(t)
PY
    "$B" periodic "$c" --overwrite > "log_${c%.toml}" 2>&1
    python3 - "${c%.toml}" "$s" "$seed" <<'PY'
import csv, sys
folder, s, seed = sys.argv[1:]
r = list(csv.DictReader(open(folder + "/summary.csv")))[0]
import re
log = open("log_" + folder).read()
m = re.search(r"drawn: ([0-9.e+-]+) to ([0-9.e+-]+) mm, mean ([0-9.e+-]+) mm", log)
sizes = ",".join(m.groups()) if m else "2,2,2"  # equal balls: the base's 2 mm
print(f"{s},{seed},{sizes},{float(r['void_ratio0']):.4f},{float(r['q_peak_kPa']):.2f},{float(r['phi_peak_deg']):.2f},"
      f"{float(r['eps_a_peak_pct']):.2f},{float(r['max_dilatancy']):.4f}", flush=True)
PY
  done
done
