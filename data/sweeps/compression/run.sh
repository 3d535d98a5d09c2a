#!/bin/bash
# K0 of one-dimensional loading against Jaky's 1 - sin(phi), phi from the same cell's periodic triaxial test.
# Run from a scratch folder: BUILD=path/to/build SRC=path/to/repository bash run.sh > k0_jaky.csv (about 3 minutes on
# one core; the 1e10 cells take most of it).
B=${BUILD:?set BUILD to the build folder}/triaxdem
echo "emod_Pa,seed,K0_at_1600kPa,K0_tangent_800_1600,phi_peak_deg_400kPa,phi_end_deg_400kPa,jaky_peak,jaky_end"
for E in 1.0e8 1.0e9 1.0e10; do for seed in 1 2 3; do
  sed "s/^mu_s = 0.15/mu_s = 0.3/; s/^emod_Pa = .*/emod_Pa = $E/; s/^seed = .*/seed = $seed/; s#^output = .*#output = \"c_${E}_$seed\"#" ${SRC:?set SRC to the repository}/tests/data/hidden_effects.toml > c_${E}_$seed.toml
  $B compression c_${E}_$seed.toml --overwrite --stresses 200,400,800,1600 > lc_${E}_$seed 2>&1
  sed "s#^output = .*#output = \"t_${E}_$seed\"#; s/^sigma3_kPa = .*/sigma3_kPa = 400/; s/^target_axial_strain_pct = .*/target_axial_strain_pct = 15.0/; s/^record_strain_pct = .*/record_strain_pct = 0.05/" c_${E}_$seed.toml > t_${E}_$seed.toml
  $B periodic t_${E}_$seed.toml --overwrite > lt_${E}_$seed 2>&1
  python3 - "$E" "$seed" <<'PY'
import csv, math, sys
E, seed = sys.argv[1], sys.argv[2]
rows = list(csv.DictReader(open(f"c_{E}_{seed}/series.csv")))
k0 = float(rows[-1]["K0"]); tan = (float(rows[-1]["sigma_h_kPa"]) - float(rows[-2]["sigma_h_kPa"])) / (float(rows[-1]["sigma_v_kPa"]) - float(rows[-2]["sigma_v_kPa"]))
s = list(csv.DictReader(open(f"t_{E}_{seed}/summary.csv")))[0]
pk = float(s["phi_peak_deg"])
ser = list(csv.DictReader(open(f"t_{E}_{seed}/series.csv")))
end = [float(r["phi_mob_deg"]) for r in ser if float(r["eps_a_pct"]) >= 14.0]
pe = sum(end) / len(end)
print(f"{E},{seed},{k0:.4f},{tan:.4f},{pk:.2f},{pe:.2f},{1-math.sin(math.radians(pk)):.4f},{1-math.sin(math.radians(pe)):.4f}", flush=True)
PY
done; done
