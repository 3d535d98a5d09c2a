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
import matplotlib.lines  # noqa: E402
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
    # The series' anisotropies are signed: + when the fabric's major direction is the stress's, - when across it.
    # A nearly isotropic network (the weak one) flips between the two from record to record, so the curves show
    # the magnitude and hollow marks the records where the direction lies across the stress.
    def anisotropy(ax, keys, title):
        for key, style in keys:
            a = np.asarray(s[key])
            line, = ax.plot(ea, np.abs(a), style, label=key)
            across = a < 0
            if across.any():
                ax.plot(ea[across], np.abs(a[across]), "o", mfc="none", ms=4, color=line.get_color())
        ax.plot([], [], "o", mfc="none", ms=4, color="0.3", label="major direction across the stress")
        ax.set_title(title, fontsize=10)
        ax.set_xlabel("axial strain (%)")
        ax.set_ylabel("anisotropy magnitude sqrt(3/2 a:a) (-)")
        ax.set_ylim(bottom=0)
        ax.legend(fontsize=8)
        ax.grid(True, lw=0.4, alpha=0.6)

    anisotropy(fig.add_subplot(gs[0, :2]), (("a_c", "-"), ("a_n", "-"), ("a_t", "-")),
               "anisotropy, all contacts (Fig. 16)")
    anisotropy(fig.add_subplot(gs[0, 2:]), (("a_c_strong", "-"), ("a_c_weak", "--"), ("a_n_strong", "-"),
                                            ("a_n_weak", "--")), "strong and weak networks (Fig. 17)")
    roses = {p: read_csv(os.path.join(run, f"micro_rose_{p}.csv")) for p in POINTS
             if os.path.exists(os.path.join(run, f"micro_rose_{p}.csv"))}
    quantities = (("density_all", "contact density"), ("fn_all_N", "normal force"),
                  ("ft_all_N", "tangential force"))
    # One radial scale for all four roses: each quantity over its largest value at A-D, so that A and D compare.
    largest = {key: max(max(r[key].max() for r in roses.values()), 1e-300) for key, _ in quantities} if roses else {}
    for k, p in enumerate(POINTS):
        if p not in roses:
            continue
        r = roses[p]
        th = np.radians(r["theta_deg"])
        # The rose in a vertical plane: theta from the z axis (up), down one side and back up the mirror side.
        ang = np.concatenate([np.pi / 2 - th, (np.pi / 2 + th)[::-1], [np.pi / 2 - th[0]]])
        pa = fig.add_subplot(gs[1, k], projection="polar")
        for key, label in quantities:
            v = r[key] / largest[key]
            pa.plot(ang, np.concatenate([v, v[::-1], [v[0]]]), label=label)
        pa.set_title(f"{p}", fontsize=10)
        pa.set_ylim(0, 1.05)
        pa.set_yticks([0.5, 1.0])
        pa.tick_params(labelsize=7)
        if k == 0:
            pa.legend(fontsize=7, loc="lower left", bbox_to_anchor=(-0.3, -0.35),
                      title="each over its largest at A-D", title_fontsize=7)
    fig.savefig(os.path.join(run, "micro_anisotropy.png"), dpi=120)

    chains = [(p, os.path.join(run, f"force_chains_{p}.vtk")) for p in POINTS]
    chains = [(p, f) for p, f in chains if os.path.exists(f)]
    if chains:
        read = [(p, read_chains(path)) for p, path in chains]
        fmax = max(max(fn.max() for _, (_, fn, _) in read), 1e-300)
        scale = 3.0 / fmax  # one width scale for every panel: a chain as thick at A as at D carries as much
        fig = plt.figure(figsize=(4 * len(chains), 4.8), constrained_layout=True)
        for k, (p, (seg, fn, strong)) in enumerate(read):
            ax = fig.add_subplot(1, len(chains), k + 1, projection="3d")
            for sel, colour in ((strong == 0, "tab:orange"), (strong == 1, "tab:green")):
                for (a, b), f in zip(seg[sel], fn[sel]):
                    ax.plot(*zip(a * 1e3, b * 1e3), color=colour, lw=0.3 + scale * f)
            ax.set_title(f"{p}: mean force {fn.mean():.2f} N", fontsize=9)
            ax.set_axis_off()
        handles = [matplotlib.lines.Line2D([], [], color="tab:green", lw=2, label="strong (above the mean force)"),
                   matplotlib.lines.Line2D([], [], color="tab:orange", lw=1, label="weak"),
                   matplotlib.lines.Line2D([], [], color="0.3", lw=0.3 + scale * fmax,
                                           label=f"width: normal force, {fmax:.1f} N widest (all panels)")]
        fig.legend(handles=handles, loc="lower center", ncol=3, fontsize=8)
        fig.savefig(os.path.join(run, "force_chains.png"), dpi=110)
    print(f"plot_micro: wrote micro_forces.png, micro_coordination.png, micro_anisotropy.png"
          f"{', force_chains.png' if chains else ''} in {run}")


if __name__ == "__main__":
    main()
