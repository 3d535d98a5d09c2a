#!/usr/bin/python3
"""Draws the micromechanics of one triaxial run like Tang et al. (2025), from the files `triaxdem triaxial`
writes with [micro] enabled:

    micro_forces.png       Figure 12: mean, strong and weak normal contact force against axial strain
    micro_coordination.png Figure 14: coordination numbers Z (with membrane contacts), Z_mech; Figure 15: O_n at peak
    micro_anisotropy.png   Figures 16 and 17: a_c, a_n, a_t of all, strong and weak networks; roses at A-D
    force_chains.png       Figure 11: force chains of the central cube at A-D (strong green, weak orange)

    /usr/bin/python3 tools/plot_micro.py out/paper_S1_100kPa

Needs Debian's python3-matplotlib and python3-numpy.
"""
import argparse
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

POINTS = ("A", "B", "C", "D")


def read_csv(path):
    try:
        with open(path, newline="") as f:
            rows = list(csv.DictReader(f))
    except OSError as e:
        sys.exit(f"plot_micro: cannot read {path}: {e.strerror}")
    if not rows:
        sys.exit(f"plot_micro: {path} has no rows")
    return {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}


def read_chains(path):
    """Segments and forces of a force_chains_*.vtk written by triaxdem (legacy ASCII polydata)."""
    with open(path) as f:
        tok = f.read().split()
    i = tok.index("POINTS")
    n = int(tok[i + 1])
    pts = np.array(tok[i + 3:i + 3 + 3 * n], dtype=float).reshape(n, 3)
    j = tok.index("normal_force_N")
    m = n // 2
    fn = np.array(tok[j + 5:j + 5 + m], dtype=float)
    k = tok.index("strong")
    strong = np.array(tok[k + 5:k + 5 + m], dtype=int)
    return pts.reshape(m, 2, 3), fn, strong


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("run", help="output folder of a triaxial run")
    run = ap.parse_args().run
    s = read_csv(os.path.join(run, "series.csv"))
    if "Z" not in s:
        sys.exit(f"plot_micro: {run}/series.csv has no micro columns (run with [micro] enabled = true)")
    ea = s["eps_a_pct"]

    fig, ax = plt.subplots(figsize=(5.5, 4), constrained_layout=True)
    for key, label in (("fn_mean_N", "mean"), ("fn_strong_N", "strong"), ("fn_weak_N", "weak")):
        ax.plot(ea, s[key], label=label)
    ax.set_xlabel("axial strain (%)")
    ax.set_ylabel("mean normal contact force (N)")
    ax.set_title("contact forces (Fig. 12)", fontsize=10)
    ax.legend()
    ax.grid(True, lw=0.4, alpha=0.6)
    fig.savefig(os.path.join(run, "micro_forces.png"), dpi=120)

    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4), constrained_layout=True)
    a1.plot(ea, s["Z"], label="Z = 2 Nc / Np (with membrane contacts)")
    a1.plot(ea, s["Z_mech"], label="Z_m (rattlers excluded)")
    a1.set_xlabel("axial strain (%)")
    a1.set_ylabel("coordination number")
    a1.set_title("coordination (Fig. 14)", fontsize=10)
    a1.legend(fontsize=8)
    a1.grid(True, lw=0.4, alpha=0.6)
    peak = os.path.join(run, "micro_coordination_peak.csv")
    if os.path.exists(peak):
        on = read_csv(peak)
        w = 0.27
        for k, (key, label) in enumerate((("particles_all", "total"), ("particles_strong", "strong"),
                                          ("particles_weak", "weak"))):
            a2.bar(on["n"] + (k - 1) * w, on[key], width=w, label=label)
        a2.set_xlabel("contacts per particle n")
        a2.set_ylabel("particles with n contacts (O_n)")
        a2.set_title("at peak q (Fig. 15)", fontsize=10)
        a2.legend(fontsize=8)
    fig.savefig(os.path.join(run, "micro_coordination.png"), dpi=120)

    fig = plt.figure(figsize=(12, 7.5), constrained_layout=True)
    gs = fig.add_gridspec(2, 4)
    ax = fig.add_subplot(gs[0, :2])
    for key, label in (("a_c", "a_c"), ("a_n", "a_n"), ("a_t", "a_t")):
        ax.plot(ea, s[key], label=label)
    ax.set_title("anisotropy, all contacts (Fig. 16)", fontsize=10)
    ax.set_xlabel("axial strain (%)")
    ax.legend(fontsize=8)
    ax.grid(True, lw=0.4, alpha=0.6)
    ax = fig.add_subplot(gs[0, 2:])
    for key, style in (("a_c_strong", "-"), ("a_c_weak", "--"), ("a_n_strong", "-"), ("a_n_weak", "--")):
        ax.plot(ea, s[key], style, label=key)
    ax.set_title("strong and weak networks (Fig. 17)", fontsize=10)
    ax.set_xlabel("axial strain (%)")
    ax.legend(fontsize=8)
    ax.grid(True, lw=0.4, alpha=0.6)
    for k, p in enumerate(POINTS):
        path = os.path.join(run, f"micro_rose_{p}.csv")
        if not os.path.exists(path):
            continue
        r = read_csv(path)
        th = np.radians(r["theta_deg"])
        # The rose in a vertical plane: theta from the z axis (up), down one side and back up the mirror side.
        ang = np.concatenate([np.pi / 2 - th, (np.pi / 2 + th)[::-1], [np.pi / 2 - th[0]]])
        pa = fig.add_subplot(gs[1, k], projection="polar")
        for key, label in (("density_all", "contact density"), ("fn_all_N", "normal force"),
                           ("ft_all_N", "tangential force")):
            v = r[key] / max(r[key].max(), 1e-300)
            pa.plot(ang, np.concatenate([v, v[::-1], [v[0]]]), label=label)
        pa.set_title(f"{p}", fontsize=10)
        pa.set_yticklabels([])
        if k == 0:
            pa.legend(fontsize=7, loc="lower left", bbox_to_anchor=(-0.3, -0.35))
    fig.savefig(os.path.join(run, "micro_anisotropy.png"), dpi=120)

    chains = [(p, os.path.join(run, f"force_chains_{p}.vtk")) for p in POINTS]
    chains = [(p, f) for p, f in chains if os.path.exists(f)]
    if chains:
        fig = plt.figure(figsize=(4 * len(chains), 4.4), constrained_layout=True)
        for k, (p, path) in enumerate(chains):
            seg, fn, strong = read_chains(path)
            ax = fig.add_subplot(1, len(chains), k + 1, projection="3d")
            scale = 3.0 / max(fn.max(), 1e-300)
            for sel, colour in ((strong == 0, "tab:orange"), (strong == 1, "tab:green")):
                for (a, b), f in zip(seg[sel], fn[sel]):
                    ax.plot(*zip(a * 1e3, b * 1e3), color=colour, lw=0.3 + scale * f)
            ax.set_title(f"{p}: mean force {fn.mean():.2f} N", fontsize=9)
            ax.set_axis_off()
        fig.savefig(os.path.join(run, "force_chains.png"), dpi=110)
    print(f"plot_micro: wrote micro_forces.png, micro_coordination.png, micro_anisotropy.png"
          f"{', force_chains.png' if chains else ''} in {run}")


if __name__ == "__main__":
    main()
