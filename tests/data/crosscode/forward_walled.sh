#!/usr/bin/env bash
# triaxdem's walled cell at a given friction (default: mu_s 0.4, mu_r 0.04, which generated the walled data), at the
# data's rate (I = 1e-3), strain (15%) and pressures, on 8 specimens per pressure (packing seeds 1-4, preparation
# friction 0.10 and 0.12, which bracket the data's void ratios), then compare_forward.py: each compared quantity at
# the data's void ratio (a line fitted over the 8), against the data and the specimens' scatter. About 5 minutes on
# 2 cores.
#   [MU_S=0.4 MU_R=0.04 DATA=walled_seed1.csv] tests/data/crosscode/forward_walled.sh [BUILD] [WORK]
# Another cell and data: BASE (a config here, default walled_base.toml), PREPS (the preparation frictions, default
# "0.10 0.12") and SEEDS (default "1 2 3 4"), as the Hertz-Mindlin law's forward run on periodic data
# (hertz_mindlin.toml says how).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
build="$(realpath "${1:-$here/../../../build}")"
work="${2:-$(mktemp -d)}"
data="$here/${DATA:-walled_seed1.csv}"
mkdir -p "$work"
pressures=$(grep -v '^#' "$data" | tail -n +2 | cut -d, -f2 | sort -un)
names=()
for p in $pressures; do for pm in ${PREPS:-0.10 0.12}; do for sd in ${SEEDS:-1 2 3 4}; do
  n="w_${p}_${pm}_s${sd}"
  sed -e "s/^mu_s = .*/mu_s = ${MU_S:-0.4}/" -e "s/^mu_r = .*/mu_r = ${MU_R:-0.04}/" \
      -e "s/^target_inertial = .*/target_inertial = 1e-3/" -e "s/^prep_mu_s = .*/prep_mu_s = $pm/" \
      -e "s/^seed = .*/seed = $sd/" -e "s/^sigma3_kPa = .*/sigma3_kPa = $p.0/" \
      -e "s/^target_axial_strain_pct = .*/target_axial_strain_pct = 15.0/" "$here/${BASE:-walled_base.toml}" > "$work/$n.toml"
  names+=("$n")
done; done; done
cores=$(nproc)  # before OMP_NUM_THREADS=1, which nproc reports as the cores
export OMP_NUM_THREADS=1 TDEM="$build/triaxdem" WORK="$work"
printf '%s\n' "${names[@]}" | xargs -P "$cores" -I{} sh -c '"$TDEM" periodic "$WORK/{}.toml" -o "$WORK/out_{}" --overwrite > "$WORK/{}.log" 2>&1'
py=python3; [ -x /usr/bin/python3 ] && py=/usr/bin/python3
"$py" "$here/compare_forward.py" "$data" "$work"
