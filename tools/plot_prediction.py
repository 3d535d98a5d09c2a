#!/usr/bin/python3
"""Draws the tests (membrane or walled) that `triaxdem calibrate` and `diagnose` predict at the calibrated parameters
beside the data, as the paper's Figure 8 sets its lab curves beside its simulations: one column per material, q (top)
and eps_v (bottom) against axial strain; each pressure one colour, each predicted specimen a line, the data as
dots (curves) or as a star at each measured peak (summary data, at the predicted peak's strain where the data
give none). Writes FOLDER/prediction.png.

Reads FOLDER/prediction_curves.csv, FOLDER/prediction.csv and, when the data had curves, FOLDER/measured_curves.csv.

    /usr/bin/python3 tools/plot_prediction.py out/calibrate_20261126-160000

Needs Debian's python3-matplotlib.
"""
import argparse
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from plot_calibration import curves, read_rows  # noqa: E402  (beside this script)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("folder", help="result folder of triaxdem calibrate or diagnose")
    ap.add_argument("-o", "--output", help="PNG file (default: FOLDER/prediction.png)")
    args = ap.parse_args()
    pred = curves(os.path.join(args.folder, "prediction_curves.csv"), by_test=True)
    table = read_rows(os.path.join(args.folder, "prediction.csv"))
    measured_path = os.path.join(args.folder, "measured_curves.csv")
    meas = curves(measured_path, by_test=True) if os.path.exists(measured_path) else {}
    materials = sorted({k[0] for k in pred})
    if not materials:
        sys.exit(f"plot_prediction: {args.folder}/prediction_curves.csv holds no curves")
    measure = table[0]["q_measure"] if table else "fixed_area"
    fig, ax = plt.subplots(2, len(materials), figsize=(max(6.0, 4.2 * len(materials)), 6.6), squeeze=False,
                           sharex=True)
    for c, m in enumerate(materials):
        pressures = sorted({k[1] for k in pred if k[0] == m})
        for i, s3 in enumerate(pressures):
            colour = f"C{i}"
            members = [k for k in pred if k[0] == m and k[1] == s3]
            for n, key in enumerate(sorted(members)):
                e, q, v = pred[key]
                ax[0][c].plot(e, q, "-", lw=1, color=colour, label=f"{s3:g} kPa, predicted" if n == 0 else None)
                ax[1][c].plot(e, v, "-", lw=1, color=colour)
            for key in (k for k in meas if k[0] == m and k[1] == s3):
                e, q, v = meas[key]
                step = max(1, len(e) // 60)
                ax[0][c].plot(e[::step], q[::step], "o", ms=3, mfc="none", color=colour, label=f"{s3:g} kPa, measured")
                ax[1][c].plot(e[::step], v[::step], "o", ms=3, mfc="none", color=colour)
            if not meas:
                for r in (r for r in table if r["material"] == m and float(r["sigma3_kPa"]) == s3):
                    e, q, _ = pred[sorted(members)[0]]
                    ax[0][c].plot([e[q.index(max(q))]], [float(r["measured_q_peak_kPa"])], "*", ms=10, color=colour,
                                  label=f"{s3:g} kPa, measured peak")
        ax[0][c].set_title(f"{m}", fontsize=10)
        ax[1][c].set_xlabel("axial strain eps_a (%)")
    ax[0][0].set_ylabel(f"deviator stress q (kPa, {measure})")
    ax[1][0].set_ylabel("volumetric strain eps_v (%, contraction +)")
    for a in ax[0]:
        a.legend(fontsize=7)
    fig.suptitle("the predicted test (membrane or walled) at the calibrated parameters (lines), the data (marks)",
                 fontsize=9)
    fig.tight_layout()
    out = args.output or os.path.join(args.folder, "prediction.png")
    fig.savefig(out, dpi=130)
    print(f"plot_prediction: wrote {out}")


if __name__ == "__main__":
    main()
