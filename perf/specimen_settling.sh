#!/usr/bin/env bash
# Does a faster specimen preparation give the same test? For each seed of SEEDS, CONFIG's specimen is built and its
# test run twice: as the config has it, and with VARIANT, a line for TABLE. A membrane test's config ([specimen]):
# VARIANT defaults to "layer_stop_ratio = 1e-2" (the layers below the top one end at an unbalanced ratio of 1e-2
# instead of the top's). A cell's config (no [specimen]: `triaxdem periodic`, periodic or walled): TABLE is
# [periodic] and VARIANT defaults to "gas_rate_per_s = 50" (the gas phase at the shipped bases' consolidation rate,
# as before the gas phase had its own). Then, per quantity, the mean difference (variant - config) over the seeds
# against the seeds' scatter:
#   the specimen      its void ratio and each layer's (membrane test); the steps and wall seconds of its preparation
#   start of shear    void ratio, coordination Z, contact-normal anisotropy a_c (series.csv's first row; a cell's
#                     a_c from the contacts of its snapshot at the shear's start)
#   the test          q_peak, q at the end, the largest dilatancy, eps_v at the end
# A difference within the scatter of one seed's value (|mean diff| below the seeds' SD) is within seed scatter.
#   perf/specimen_settling.sh     # CONFIG=configs/small/S3_300kPa.toml SEEDS="1 2 3" NP=$(nproc) BUILD=build
#                                 # WORK=runs/specimen_settling VARIANT="layer_stop_ratio = 1e-2" TABLE=specimen
# About 4 minutes a seed for the small case on 2 cores; seconds a seed for the calibration's cells.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
. "$root/scripts/script_folders.sh"
build="$(build_folder specimen_settling)"; work="$(realpath -m "${WORK:-$root/runs/specimen_settling}")"
config="$(realpath "${CONFIG:-$root/configs/small/S3_300kPa.toml}")"
seeds="${SEEDS:-1 2 3}"; np="${NP:-$(nproc)}"
if grep -q '^\[specimen\]' "$config"; then
  command=triaxial; table="${TABLE:-specimen}"; variant="${VARIANT:-layer_stop_ratio = 1e-2}"
else
  command=periodic; table="${TABLE:-periodic}"; variant="${VARIANT:-gas_rate_per_s = 50}"
fi
tdem="$build/triaxdem"
[ -x "$tdem" ] || { echo "specimen_settling: build triaxdem first ($tdem)"; exit 1; }
py=python3; [ -x /usr/bin/python3 ] && py=/usr/bin/python3
fresh_folder specimen_settling "$work"
export OMP_NUM_THREADS="$np" OMP_PROC_BIND=spread OMP_PLACES=threads
for seed in $seeds; do
  for kind in config variant; do
    cfg="$work/${kind}_$seed.toml"
    # The config's own folder keeps its relative paths; the seed in [run], the variant's line in its table.
    awk -v seed="$seed" -v kind="$kind" -v line="$variant" -v table_line="[$table]" '
      /^\[/ { table = $0 }
      table == "[run]" && /^seed *=/ { print "seed = " seed; next }
      { print }
      $0 == table_line && kind == "variant" { print line }
    ' "$config" > "$cfg"
    grep -q "^seed = $seed" "$cfg" || { echo "specimen_settling: $config has no [run] seed line"; exit 1; }
    echo "== seed $seed, $kind"
    (cd "$(dirname "$config")" && "$tdem" "$command" "$cfg" -o "$work/$kind/$seed/test") > "$work/${kind}_$seed.log" 2>&1
  done
done
"$py" - "$work" "$seeds" <<'PY'
import csv, glob, os, re, statistics, sys
work, seeds = sys.argv[1], sys.argv[2].split()
def rows(path): return list(csv.DictReader(l for l in open(path) if not l.startswith("#")))
def fabric(snapshot):
    """a_c of the ball-ball contact normals (host/engine/micro.cpp's: 7.5 dev<nn>, its magnitude sqrt(1.5 a:a),
    signed + where it favours z)."""
    import h5py, numpy as np
    with h5py.File(snapshot, "r") as f:
        n = np.asarray(f["contacts/normal"])[np.asarray(f["contacts/boundary"]) == 0]
    a = 7.5 * (n.T @ n / len(n) - np.eye(3) / 3)
    return (1 if a[2, 2] >= 0 else -1) * (1.5 * (a * a).sum()) ** 0.5
def values(kind, seed):
    d = f"{work}/{kind}/{seed}/test"
    v = {}
    s = rows(d + "/summary.csv")[0]
    series = rows(d + "/series.csv")
    if os.path.exists(d + "/layers.csv"):
        for l in rows(d + "/layers.csv"): v["layer %s e" % l["layer"]] = float(l["void_ratio"])
        timing = [t for t in rows(d + "/timings.csv") if t["stage"].startswith("specimen")]
        v["specimen steps"] = sum(int(t["steps"]) for t in timing)
        v["specimen wall s"] = sum(float(t["wall_s"]) for t in timing)
        v["Z at shear start"] = float(series[0]["Z"])
        v["a_c at shear start"] = float(series[0]["a_c"])
    else:
        # A cell's preparation is in its log only: "preparation consolidation ... done in 0m01s (converged after N steps)".
        log = open(f"{work}/{kind}_{seed}.log").read().replace("\r", "\n")
        m = re.findall(r"preparation consolidation.*done in (\d+)m(\d+)s \(converged after (\d+) steps\)", log)
        v["specimen steps"] = int(m[-1][2]) if m else 0
        v["specimen wall s"] = 60 * int(m[-1][0]) + int(m[-1][1]) if m else 0
        v["Z at shear start"] = float(series[0]["coordination"])
        v["a_c at shear start"] = fabric(min(glob.glob(d + "/snap_*.h5")))
    v["e at shear start"] = float(s["void_ratio0"])
    v["q_peak kPa"] = float(s["q_peak_kPa"])
    v["q_end kPa"] = float(s["q_end_kPa"])
    v["max dilatancy"] = float(s["max_dilatancy"])
    v["eps_v end %"] = float(series[-1]["eps_v_pct"])
    return v
base = [values("config", s) for s in seeds]
var = [values("variant", s) for s in seeds]
print("%-22s %12s %12s %12s %10s  %s" % ("quantity", "config mean", "variant mean", "mean diff", "seed SD",
                                        "(diff over SD)"))
for k in base[0]:
    a = [b[k] for b in base]; b = [w[k] for w in var]
    diff = statistics.mean(y - x for x, y in zip(a, b))
    sd = statistics.stdev(a) if len(a) > 1 else float("nan")
    print("%-22s %12.5g %12.5g %12.4g %10.4g  %s" % (k, statistics.mean(a), statistics.mean(b), diff, sd,
          "" if k.startswith("specimen") else "%.2f" % (abs(diff) / sd if sd > 0 else float("inf"))))
PY
