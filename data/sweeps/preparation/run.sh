#!/bin/bash
# Does the stiffness a specimen is prepared with move its triaxial test? (issue 88: a calibration with emod free runs
# cells prepared once at the base's emod against data whose specimens the material prepared at its own.) The
# hidden-effect cell (tests/data/hidden_effects.toml, 120 balls, preparation friction 0.03) at emod 2e8 Pa, mu_s 0.25:
# SPECIMENS packing seeds prepared at emod 2e8 (the reference) and 1e8, each tested at 2e8 and 0.25 at 100, 200 and
# 300 kPa (perf/inertial_scan --preparation-emod); and the same specimens at mu_s 0.30, the friction's effect to read
# the shift in units of mu_s. Writes preparation.csv and friction.csv (a row per level, pressure and feature) and
# scan.log. About 15 minutes on 2 cores with SPECIMENS=32 (192 + 96 runs of 1-2 s each, two at a time).
#   BUILD=path/to/build SRC=path/to/repository SPECIMENS=32 bash run.sh   (from a scratch folder)
set -euo pipefail
scan=${BUILD:?set BUILD to the build folder}/perf/inertial_scan
base=${SRC:?set SRC to the repository}/tests/data/hidden_effects.toml
n=${SPECIMENS:-32}
model() {  # MU_S: the tested model's config
  sed -e 's/^emod_Pa = .*/emod_Pa = 2.0e8/' -e "s/^mu_s = .*/mu_s = $1/" "$base"
}
echo "$n" > n
model 0.25 > truth.toml
model 0.30 > friction.toml
"$scan" --config truth.toml --specimens "$n" --pressures 100,200,300 --preparation-emod 2e8,1e8 -j 2 \
  -o preparation.csv | tee scan.log
# The friction's effect: the reference specimens (prepared at 2e8) tested at mu_s 0.30.
"$scan" --config friction.toml --specimens "$n" --pressures 100,200,300 --preparation-emod 2e8 -j 2 \
  -o friction.csv | tee -a scan.log
# summary.csv: per pressure, the peak's shift (q_peak / sigma3) from a preparation at 1e8 instead of 2e8, with its
# standard error over the specimens, and the same in mu_s through the friction's effect on the peak.
python3 - <<'PY'
import csv, math
rows = lambda f: [r for r in csv.DictReader(open(f)) if r["feature"] == "q" and float(r["strain_pct"]) == 0]
prep = {r["sigma3_kPa"]: r for r in rows("preparation.csv") if float(r["preparation_emod_Pa"]) != 2e8}
ref = {r["sigma3_kPa"]: float(r["reference_mean"]) for r in rows("preparation.csv")}
fric = {r["sigma3_kPa"]: float(r["reference_mean"]) for r in rows("friction.csv")}
n = int(open("n").read())
with open("summary.csv", "w") as f:
    f.write("sigma3_kPa,qpeak_over_sigma3_prep2e8,shift_prep1e8,shift_se,dq_dmu_s,mu_s_equivalent,mu_s_se\n")
    for s3, r in prep.items():
        shift, se = float(r["mean_shift"]), float(r["shift_sd"]) / math.sqrt(n)
        slope = (fric[s3] - ref[s3]) / 0.05
        f.write(f"{s3},{ref[s3]:.4f},{shift:.4f},{se:.4f},{slope:.3f},{-shift / slope:.4f},{se / slope:.4f}\n")
PY
cat summary.csv
