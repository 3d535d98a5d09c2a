#!/usr/bin/python3
"""Compares what Tang et al. (2025) report in words about the micromechanics (data/paper_micro_observations.csv)
with a triaxdem run of the same case (S-1 at 100 kPa), and with a study for the cross-case figures. Writes a
Markdown table to stdout and to RUN/micro_comparison.md.

    /usr/bin/python3 tools/compare_micro.py out/paper/S1_100kPa --study out/paper

The paper's mean contact forces are read in its 20 mm central cube, so the run's rve_ columns are used.
Definitions used here (the paper gives none): strong contacts have fn above the mean; a particle belongs to
a network when it has at least one contact of it; the coordination plateau starts where 90% of the fall of Z
from its maximum to its mean over the last third is done; the peak of anisotropy is the maximum of a_n.
"""
import argparse
import csv
import os
import sys

import numpy as np


def read_rows(path):
    try:
        with open(path, newline="") as f:
            return list(csv.DictReader(r for r in f if not r.startswith("#")))
    except OSError as e:
        sys.exit(f"compare_micro: cannot read {path}: {e.strerror}")


def columns(path):
    rows = read_rows(path)
    if not rows:
        sys.exit(f"compare_micro: {path} has no rows")
    return {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}


def at(s, key, eps):
    return float(np.interp(eps, s["eps_a_pct"], s[key]))


def plateau_start(ea, z):
    """First strain after the maximum of Z where 90% of its fall to the final level (mean of the last third)
    is done."""
    level = z[ea >= ea[-1] * 2 / 3].mean()
    k = int(np.argmax(z))
    drop = z[k] - level
    after = np.nonzero(z[k:] - level <= 0.1 * drop)[0]
    return float(ea[k + after[0]]) if len(after) else float(ea[-1])


def main():
    root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("run", help="output folder of the S-1, 100 kPa triaxial run")
    ap.add_argument("--study", help="output folder of a study with S1/S2/S3 at 100-300 kPa (cross-case rows)")
    ap.add_argument("--observations", default=os.path.join(root, "data", "paper_micro_observations.csv"))
    args = ap.parse_args()
    s = columns(os.path.join(args.run, "series.csv"))
    if "rve_fn_mean_N" not in s:
        sys.exit(f"compare_micro: {args.run}/series.csv has no micro columns (run with [micro] enabled)")
    ea, q = s["eps_a_pct"], s["q_kPa"]
    ipk = int(np.argmax(q))
    ours = {
        "mean_contact_force_at_0pct_strain": (at(s, "rve_fn_mean_N", 0), "central cube, all contacts"),
        "mean_contact_force_at_1pct_strain": (at(s, "rve_fn_mean_N", 1), "central cube"),
        "mean_contact_force_at_peak_5pct": (float(s["rve_fn_mean_N"][ipk]), f"central cube, at peak q ({ea[ipk]:.1f}%)"),
        "mean_contact_force_at_15pct": (float(s["rve_fn_mean_N"][-1]), f"central cube, at {ea[-1]:.1f}%"),
        "strain_at_peak_anisotropy": (float(ea[int(np.argmax(s["a_n"]))]), "maximum of a_n"),
        "coordination_plateau_from_strain": (plateau_start(ea, s["Z"]), "90% of the fall of Z from its maximum done"),
        "strong_to_weak_contact_force_ratio": (float(s["fn_ratio_strong_weak"][ipk]), "mean fn, at peak q"),
        "weak_to_strong_particle_ratio": (float(s["particles_weak"][ipk] / max(s["particles_strong"][ipk], 1)),
                                          "balls with a weak / a strong contact, at peak q"),
    }
    peak = os.path.join(args.run, "micro_coordination_peak.csv")
    if os.path.exists(peak):
        on = columns(peak)
        ours["coordination_mode_at_peak"] = (float(on["n"][int(np.argmax(on["particles_all"]))]), "all networks")
    if args.study:
        cases = {r["case"]: r for r in read_rows(os.path.join(args.study, "study_summary.csv")) if r["status"] == "ok"}
        def phi(mat):
            v = [float(r["phi_peak_deg"]) for k, r in cases.items() if k.startswith(mat)]
            return np.mean(v) if v else float("nan")
        for m, key in (("S2", "peak_friction_angle_gain_S2_vs_S1"), ("S3", "peak_friction_angle_gain_S3_vs_S1")):
            ours[key] = (100 * (phi(m) / phi("S1") - 1), "mean peak friction angle over the pressures")
        if "S1_100kPa" in cases and "S1_300kPa" in cases:
            z = [columns(os.path.join(args.study, c, "series.csv")) for c in ("S1_100kPa", "S1_300kPa")]
            tails = [x["Z"][x["eps_a_pct"] >= x["eps_a_pct"][-1] * 2 / 3].mean() for x in z]
            ours["coordination_increase_100_to_300kPa"] = (100 * (tails[1] / tails[0] - 1), "Z plateau, S-1")
    lines = ["| quantity | paper | triaxdem | unit | how triaxdem measures it |", "|---|---|---|---|---|"]
    for r in read_rows(args.observations):
        v, how = ours.get(r["quantity"], (float("nan"), "not measured (needs --study)"))
        lines.append(f"| {r['quantity']} | {r['value']} | {v:.3g} | {r['unit']} | {how} |")
    text = "\n".join(lines) + "\n"
    print(text, end="")
    with open(os.path.join(args.run, "micro_comparison.md"), "w") as f:
        f.write(text)


if __name__ == "__main__":
    main()
