#!/usr/bin/python3
"""Draws a study's figure like Figure 8 of Tang et al. (2025): one column per confining pressure, deviator
stress q (top) and volumetric strain eps_v (bottom, contraction positive) against axial strain, one curve per
case (with the peaks of `study --compare` files as horizontal lines), and writes STUDY/study.png; with the
runs' micro columns also STUDY/study_networks.png (Figure 10).

Reads STUDY/study_summary.csv (written by `triaxdem study`) and each case's STUDY/<case>/series.csv.

    /usr/bin/python3 tools/plot_study.py out/study

Needs Debian's python3-matplotlib and python3-numpy.
"""
import argparse
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from _csv_rows import read_rows  # noqa: E402



def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("study", help="output folder of `triaxdem study`")
    ap.add_argument("-o", "--output", help="PNG file (default: STUDY/study.png)")
    args = ap.parse_args()
    cases = [r for r in read_rows(os.path.join(args.study, "study_summary.csv")) if r["status"] == "ok"]
    if not cases:
        sys.exit(f"plot_study: {args.study}/study_summary.csv lists no finished case")
    pressures = sorted({float(r["sigma3_kPa"]) for r in cases})
    materials = sorted({(float(r["mu_s"]), float(r["mu_r"])) for r in cases})
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    compared = [k[len("q_peak_"):-len("_kPa")] for k in cases[0] if k.startswith("q_peak_") and k != "q_peak_kPa"]
    fig, axes = plt.subplots(2, len(pressures), figsize=(4.2 * len(pressures), 7), squeeze=False,
                             constrained_layout=True)
    for r in cases:
        rows = read_rows(os.path.join(args.study, r["case"], "series.csv"))
        ea = np.array([float(x["eps_a_pct"]) for x in rows])
        q = np.array([float(x["q_kPa"]) for x in rows])
        ev = np.array([float(x["eps_v_pct"]) for x in rows])
        col = pressures.index(float(r["sigma3_kPa"]))
        colour = colours[materials.index((float(r["mu_s"]), float(r["mu_r"]))) % len(colours)]
        label = f"{r['case']}: mu_s {float(r['mu_s']):g}, mu_r {float(r['mu_r']):g}"
        axes[0][col].plot(ea, q, color=colour, lw=1.3, label=f"{label} (q_peak {float(r['q_peak_kPa']):.0f} kPa)")
        axes[1][col].plot(ea, ev, color=colour, lw=1.3, label=label)
        # Peaks of the files given to `study --compare`, as horizontal lines in the case's colour.
        for stem, style in zip(compared, ("--", ":", "-.")):
            value = r.get(f"q_peak_{stem}_kPa", "")
            if value:
                axes[0][col].axhline(float(value), color=colour, ls=style, lw=0.9,
                                     label=f"{r['case']}, {stem}: {float(value):.0f} kPa")
    for col, p in enumerate(pressures):
        axes[0][col].set_title(f"sigma3 = {p:g} kPa", fontsize=10)
        axes[0][col].set_ylabel("deviator stress q (kPa)")
        axes[1][col].set_ylabel("volumetric strain eps_v (%), contraction +")
        axes[1][col].axhline(0, color="0.6", lw=0.8)
        for row in (0, 1):
            ax = axes[row][col]
            ax.set_xlabel("axial strain eps_a (%)")
            ax.set_xlim(left=0)
            ax.grid(True, lw=0.4, alpha=0.6)
            ax.legend(fontsize=7, loc="best")
        axes[0][col].set_ylim(bottom=0)
    out = args.output or os.path.join(args.study, "study.png")
    fig.savefig(out, dpi=120)
    print(f"plot_study: wrote {out}")
    figure_10(args.study, cases, pressures)


def figure_10(study, cases, pressures):
    """Strong/weak ratios of the mean normal and tangential contact force at peak q against mu_s, one line
    per confining pressure, like the paper's Figure 10 (needs the runs' micro columns)."""
    points = {}
    for r in cases:
        rows = read_rows(os.path.join(study, r["case"], "series.csv"))
        if not rows or "fn_ratio_strong_weak" not in rows[0]:
            return
        peak = max(rows, key=lambda x: float(x["q_kPa"]))
        points.setdefault(float(r["sigma3_kPa"]), []).append(
            (float(r["mu_s"]), float(peak["fn_ratio_strong_weak"]), float(peak["ft_ratio_strong_weak"])))
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 4), constrained_layout=True)
    for p in pressures:
        v = sorted(points.get(p, []))
        if not v:
            continue
        mu, fn, ft = zip(*v)
        a1.plot(mu, fn, "o-", label=f"{p:g} kPa")
        a2.plot(mu, ft, "s-", label=f"{p:g} kPa")
    a1.set_ylabel("strong / weak mean normal force")
    a2.set_ylabel("strong / weak mean tangential force")
    for ax in (a1, a2):
        ax.set_xlabel("sliding friction mu_s")
        ax.grid(True, lw=0.4, alpha=0.6)
        ax.legend(fontsize=8)
    fig.suptitle("at peak deviator stress (Fig. 10)", fontsize=10)
    out = os.path.join(study, "study_networks.png")
    fig.savefig(out, dpi=120)
    print(f"plot_study: wrote {out}")


if __name__ == "__main__":
    main()
