#!/usr/bin/python3
"""Draws measured against simulated results of `triaxdem calibrate` or `triaxdem diagnose`: with measured
curves, one column per material and pressure of q and eps_v against axial strain (measured as dots, simulated
as lines); with summary data only, q_peak against sigma3 per material and the simulated curves. Writes FOLDER/calibration.png.

Reads FOLDER/simulated_curves.csv, FOLDER/measured_curves.csv (when the data had curves), FOLDER/errors.csv and,
from diagnose, FOLDER/extended_curves.csv (the extended model, drawn dashed).

    /usr/bin/python3 tools/plot_calibration.py out/calibrate_20261122-181845

Needs Debian's python3-matplotlib.
"""
import argparse
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read_rows(path):
    try:
        with open(path, newline="") as f:
            return list(csv.DictReader(line for line in f if not line.startswith("#")))
    except OSError as e:
        sys.exit(f"plot_calibration: cannot read {path}: {e.strerror}")


def curves(path, by_test=False):
    """{(material, sigma3_kPa): (eps_a, q, eps_v)} in %, kPa, % (eps_v NaN where the file has none); with
    by_test, keyed (material, sigma3_kPa, test label) so that replicates stay apart."""
    out = {}
    for r in read_rows(path):
        key = (r["material"], float(r["sigma3_kPa"])) + ((r.get("test", ""),) if by_test else ())
        e, q, v = out.setdefault(key, ([], [], []))
        e.append(float(r["eps_a_pct"]))
        q.append(float(r["q_kPa"]))
        v.append(float(r["eps_v_pct"]) if r.get("eps_v_pct") not in (None, "") else float("nan"))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("folder", help="result folder of triaxdem calibrate or diagnose")
    ap.add_argument("-o", "--output", help="PNG file (default: FOLDER/calibration.png)")
    args = ap.parse_args()
    sim = curves(os.path.join(args.folder, "simulated_curves.csv"))
    ext_path = os.path.join(args.folder, "extended_curves.csv")  # diagnose: the extended model, dashed
    ext = curves(ext_path) if os.path.exists(ext_path) else {}
    measured_path = os.path.join(args.folder, "measured_curves.csv")
    out = args.output or os.path.join(args.folder, "calibration.png")
    if os.path.exists(measured_path):
        meas = curves(measured_path)
        keys = sorted(meas)
        fig, ax = plt.subplots(2, len(keys), figsize=(3.6 * len(keys), 6.4), squeeze=False, sharex=True)
        for c, key in enumerate(keys):
            e, q, v = meas[key]
            step = max(1, len(e) // 150)  # dots, not a smear
            ax[0][c].plot(e[::step], q[::step], ".", ms=3, color="0.45", label="measured")
            ax[1][c].plot(e[::step], v[::step], ".", ms=3, color="0.45")
            if key in sim:
                es, qs, vs = sim[key]
                ax[0][c].plot(es, qs, "-", color="C3", label="simulated (base model)" if ext else "simulated")
                ax[1][c].plot(es, vs, "-", color="C3")
            if key in ext:
                es, qs, vs = ext[key]
                ax[0][c].plot(es, qs, "--", color="C0", label="extended model")
                ax[1][c].plot(es, vs, "--", color="C0")
            ax[0][c].set_title(f"{key[0]}, sigma3 = {key[1]:g} kPa", fontsize=9)
            ax[1][c].set_xlabel("axial strain eps_a (%)")
        ax[0][0].set_ylabel("deviator stress q (kPa)")
        ax[1][0].set_ylabel("volumetric strain eps_v (%, contraction +)")
        ax[0][0].legend(fontsize=8)
    else:
        rows = [r for r in read_rows(os.path.join(args.folder, "errors.csv")) if r["quantity"] == "q_peak"]
        materials = sorted({r["material"] for r in rows})
        # Left: q_peak against sigma3; right: the simulated curves, with each measured peak as a mark at the
        # simulated peak's strain (the data give no strain).
        fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.2))
        for k, m in enumerate(materials):
            mine = sorted((float(r["sigma3_kPa"]), float(r["measured"]), float(r["simulated"]))
                          for r in rows if r["material"] == m)
            s3 = [x[0] for x in mine]
            ax1.plot(s3, [x[1] for x in mine], "o", color=f"C{k}", label=f"{m} measured")
            ax1.plot(s3, [x[2] for x in mine], "x--", color=f"C{k}", label=f"{m} simulated")
            for s3k, qm, _ in mine:
                if (m, s3k) not in sim:
                    continue
                es, qs, _ = sim[(m, s3k)]
                ax2.plot(es, qs, "-", color=f"C{k}", lw=1, label=f"{m}" if s3k == s3[0] else None)
                ax2.plot([es[qs.index(max(qs))]], [qm], "o", color=f"C{k}", ms=5)
                if (m, s3k) in ext:
                    ax2.plot(ext[(m, s3k)][0], ext[(m, s3k)][1], "--", color=f"C{k}", lw=0.8)
        ax1.set_xlabel("confining pressure sigma3 (kPa)")
        ax1.set_ylabel("peak deviator stress q_peak (kPa)")
        ax1.legend(fontsize=8)
        ax2.set_xlabel("axial strain eps_a (%)")
        ax2.set_ylabel("deviator stress q (kPa)")
        ax2.set_title("calibrated model (lines; extended, dashed), measured peaks (dots)", fontsize=9)
        ax2.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=130)
    print(f"plot_calibration: wrote {out}")


if __name__ == "__main__":
    main()
