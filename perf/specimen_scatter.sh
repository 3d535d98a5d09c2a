#!/usr/bin/env bash
# How a periodic cell's scatter falls with its size (host/fit/misfit.hpp, kSpecimenScatterExponent): the hidden-effect
# simulator (tests/data/hidden_effects.toml, base model) in cells of 120, 480 and 1920 balls (the box scaled to the
# same solid fraction), SEEDS specimens a size at 100 and 300 kPa, then q / sigma3 and eps_v read at 0.05-8% strain
# and the exponent a of sd ~ N^-a between the sizes, with each size's mean and its standard error
# (tools/specimen_scatter.py). SMALL_PREP_MU_S prepares the 120-ball cells with that friction instead of the
# config's, to set them at the larger cells' void ratio as diagnose matches a specimen's state (0.012 for 0.03).
# About 10 minutes on 2 cores.
#   bash perf/specimen_scatter.sh              # SEEDS=12 FACTORS="1 4 16" BUILD=build WORK=runs/specimen_scatter SMALL_PREP_MU_S=
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
. "$root/scripts/script_folders.sh"
build="$(build_folder specimen_scatter)"; work="$(realpath -m "${WORK:-$root/runs/specimen_scatter}")"
seeds="${SEEDS:-12}"; factors="${FACTORS:-1 4 16}"
mkdir -p "$work"
for s3 in 100 300; do
  for factor in $factors; do
    n=$((120 * factor)); edge=$(awk -v f="$factor" 'BEGIN { printf "%.4f", 14.5 * f ^ (1 / 3) }')
    for ((seed = 1; seed <= seeds; ++seed)); do
      cfg="$work/n${n}_${s3}_$seed.toml"
      sed -e "s/^seed = .*/seed = $((1000 + seed))/" -e "s/^sigma3_kPa = .*/sigma3_kPa = $s3.0/" \
          -e "s/^count = .*/count = $n/" -e "s/^size_mm = .*/size_mm = [$edge, $edge, $edge]/" \
          "$root/tests/data/hidden_effects.toml" > "$cfg"
      if [ "$factor" = 1 ] && [ -n "${SMALL_PREP_MU_S:-}" ]; then sed -i "s/^prep_mu_s = .*/prep_mu_s = $SMALL_PREP_MU_S/" "$cfg"; fi
      "$build/triaxdem" periodic "$cfg" -o "$work/n${n}_${s3}_$seed" --overwrite > "$work/n${n}_${s3}_$seed.log" 2>&1
      echo "specimen scatter: $n balls, $s3 kPa, specimen $seed of $seeds done"
    done
  done
done
/usr/bin/python3 "$root/tools/specimen_scatter.py" "$work"
