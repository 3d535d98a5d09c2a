#!/usr/bin/python3
"""Plots triaxial runs like Figure 8 of Tang et al. (2025): deviator stress q and volumetric strain eps_v
against axial strain eps_a, in two panels, for one run or several overlaid.

Reads the series.csv of a run (columns eps_a_pct, q_kPa, eps_v_pct, as `triaxdem triaxial` and `periodic` write;
with sigma1_bottom_kPa, as the membrane test writes, q from the bottom platen is drawn dashed);
a RUN argument may be the output folder or the CSV file itself. Conventions: eps_a = (h0 - h)/h0,
eps_v = -(V - V0)/V0 (contraction positive); q = sigma1 - sigma3 with the cell pressure (membrane test) or
sigma1 - (sigma2 + sigma3)/2 with the lateral stresses measured from the contacts (periodic cell).

    /usr/bin/python3 tools/plot_triaxial.py out/periodic_S1_100kPa
    /usr/bin/python3 tools/plot_triaxial.py out/a out/b -l "mu_s 0.15" "mu_s 0.3" -o compare.png

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

NEEDED = ("eps_a_pct", "q_kPa", "eps_v_pct")


def read_series(run):
    """Columns of a run's series.csv as a dict of float arrays; exits with a message naming the file."""
    path = os.path.join(run, "series.csv") if os.path.isdir(run) else run
    try:
        with open(path, newline="") as f:
            rows = list(csv.reader(f))
    except OSError as e:
        sys.exit(f"plot_triaxial: cannot read {path}: {e.strerror}")
    if len(rows) < 2:
        sys.exit(f"plot_triaxial: {path} has no data rows")
    header = rows[0]
    missing = [c for c in NEEDED if c not in header]
    if missing:
        sys.exit(f"plot_triaxial: {path} lacks the column(s) {', '.join(missing)} (has: {', '.join(header)})")
    data = np.array([[float(v) for v in r] for r in rows[1:] if r], dtype=float)
    return path, {name: data[:, k] for k, name in enumerate(header)}


def summary_peak(series_path):
    """(q_peak kPa, eps_a at peak %) from the summary.csv beside a series.csv, None when there is none."""
    try:
        with open(os.path.join(os.path.dirname(series_path), "summary.csv"), newline="") as f:
            row = next(csv.DictReader(f))
        return float(row["q_peak_kPa"]), float(row["eps_a_peak_pct"])
    except (OSError, StopIteration, KeyError, ValueError):
        return None


def value_at(x, y, x0):
    return float(np.interp(x0, x, y))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("runs", nargs="+", help="output folder(s) of runs, or series.csv file(s)")
    ap.add_argument("-l", "--labels", nargs="+", help="legend labels, one per run (default: folder names)")
    ap.add_argument("-o", "--output", help="PNG file (default: triaxial.png in the first run's folder)")
    ap.add_argument("--marks", default="0,1,5,15",
                    help="axial strains (%%) starred and lettered A, B, ... on the first run, like Figure 8 "
                         "(default 0,1,5,15; empty for none)")
    ap.add_argument("--title", default=None, help="figure title")
    args = ap.parse_args()
    if args.labels and len(args.labels) != len(args.runs):
        sys.exit(f"plot_triaxial: {len(args.labels)} labels for {len(args.runs)} runs")

    fig, (ax_q, ax_v) = plt.subplots(1, 2, figsize=(11, 4.4), constrained_layout=True)
    first_path = None
    for k, run in enumerate(args.runs):
        path, s = read_series(run)
        first_path = first_path or path
        ea, q, ev = s["eps_a_pct"], s["q_kPa"], s["eps_v_pct"]
        name = args.labels[k] if args.labels else os.path.basename(os.path.dirname(os.path.abspath(path)))
        peak = summary_peak(path)
        if peak:  # the program's peak: of the moving mean over +-0.25% strain, as measured curves are summarised
            label = f"{name}: q_peak {peak[0]:.1f} kPa at {peak[1]:.1f}% (moving mean)"
        else:
            ipk = int(np.argmax(q))
            peak = (q[ipk], ea[ipk])
            label = f"{name}: highest record {peak[0]:.1f} kPa at {peak[1]:.1f}%"
        line, = ax_q.plot(ea, q, lw=1.4, label=label)
        ax_q.plot(peak[1], peak[0], "o", ms=4, color=line.get_color())
        if "sigma1_bottom_kPa" in s and "sigma3_kPa" in s:
            # q is read at the top platen, which drives the test; the bottom platen shows what reaches the far
            # end (they differ by what the balls' local damping takes out of the axial flow: docs/performance.md).
            ax_q.plot(ea, s["sigma1_bottom_kPa"] - s["sigma3_kPa"], lw=0.8, ls="--", color=line.get_color(),
                      label=f"{name}: bottom platen")
        ax_v.plot(ea, ev, lw=1.4, color=line.get_color(), label=name)
        if k == 0 and args.marks:
            for j, m in enumerate(float(v) for v in args.marks.split(",")):
                if m > ea[-1] + 1e-9:
                    continue
                letter = chr(ord("A") + j)
                for ax, y in ((ax_q, q), (ax_v, ev)):
                    yv = value_at(ea, y, m)
                    ax.plot(m, yv, "*", ms=11, color="black", zorder=5)
                    ax.annotate(letter, (m, yv), textcoords="offset points", xytext=(4, 5), fontsize=9)

    ax_q.set_xlabel(r"axial strain $\varepsilon_a$ (%)")
    ax_q.set_ylabel(r"deviator stress $q$ (kPa)")
    ax_q.set_title("(a) stress-strain", loc="left", fontsize=10)
    ax_v.set_xlabel(r"axial strain $\varepsilon_a$ (%)")
    ax_v.set_ylabel(r"volumetric strain $\varepsilon_v$ (%), contraction +")
    ax_v.set_title("(b) volumetric strain", loc="left", fontsize=10)
    ax_v.axhline(0, color="0.6", lw=0.8)
    for ax in (ax_q, ax_v):
        ax.set_xlim(left=0)
        ax.grid(True, lw=0.4, alpha=0.6)
        ax.legend(fontsize=8, loc="best")
    ax_q.set_ylim(bottom=0)
    if args.title:
        fig.suptitle(args.title)
    out = args.output or os.path.join(os.path.dirname(os.path.abspath(first_path)), "triaxial.png")
    fig.savefig(out, dpi=130)
    print(f"plot_triaxial: wrote {out}")


if __name__ == "__main__":
    main()
