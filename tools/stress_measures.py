#!/usr/bin/env python3
"""The deviator of membrane triaxial runs by each lab measure, and the specimen's mean stress beside it.

Reads RUN/series.csv (and RUN/summary.csv where present) of runs of `triaxdem triaxial`, and of `triaxdem
periodic` for comparison, and prints a Markdown table: the peak of each measure of q (the moving-mean peaks
of summary.csv), and at the highest record of the fixed-area q the stress ratio q/p read four ways: at the
platen with the fixed area and the cell pressure (the paper's), with the enclosed volume and the lateral stress
the balls receive (area and membrane corrected), from every contact (Love-Weber), and the periodic cell's.
docs/running.md, "Which q", defines the columns.

    tools/stress_measures.py out/small_S1_100kPa [out/periodic_S1_100kPa ...]
"""
import argparse
import csv
import os
import sys


def read_rows(path):
    try:
        with open(path, newline="") as f:
            return [r for r in csv.DictReader(line for line in f if not line.startswith("#"))]
    except OSError as e:
        sys.exit(f"stress_measures: {path}: {e.strerror}")


def number(row, key, path):
    try:
        return float(row[key])
    except (KeyError, TypeError, ValueError):
        sys.exit(f"stress_measures: {path}: column '{key}' missing or not a number (a run of an older program?)")


def summary(run):
    path = os.path.join(run, "summary.csv")
    rows = read_rows(path) if os.path.exists(path) else []
    return rows[0] if rows else {}


def describe(run):
    path = os.path.join(run, "series.csv")
    rows = read_rows(path)
    if not rows:
        sys.exit(f"stress_measures: {path}: no rows")
    s = summary(run)
    top = max(rows, key=lambda r: number(r, "q_kPa", path))
    q, s3 = number(top, "q_kPa", path), number(top, "sigma3_kPa", path)
    out = {"run": run, "eps": number(top, "eps_a_pct", path), "periodic": "q_area_kPa" not in top}
    # A periodic cell's p is its own mean stress (its sigma2 and sigma3 are servoed apart).
    out["qp_platen"] = q / (number(top, "p_kPa", path) if out["periodic"] else s3 + q / 3)
    out["peaks"] = {k: float(s[k]) if s.get(k) not in (None, "") else None
                    for k in ("q_peak_kPa", "q_peak_area_kPa", "q_peak_parabolic_kPa", "q_peak_membrane_kPa",
                              "q_peak_lw_kPa")}
    if out["periodic"]:
        return out
    q_area, s3_balls = number(top, "q_area_kPa", path), number(top, "sigma3_balls_kPa", path)
    q_mem = number(top, "q_membrane_kPa", path)
    out["qp_corrected"] = q_mem / (s3_balls + q_mem / 3)
    out["qp_lw"] = number(top, "q_lw_kPa", path) / number(top, "p_lw_kPa", path)
    out["area_ratio"] = (q + s3) / (q_area + s3)
    out["membrane_kPa"] = s3_balls - s3
    out["hoop_kPa"] = number(top, "sigma3_hoop_kPa", path) - s3
    out["q_net"] = number(top, "q_net_kPa", path)
    return out


def cell(v, fmt):
    return fmt.format(v) if v is not None else "-"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("runs", nargs="+", help="output folders of triaxial or periodic runs")
    args = ap.parse_args()
    runs = [describe(r) for r in args.runs]
    print("| run | q_peak fixed area | area corrected | parabolic | membrane corrected | Love-Weber | kPa |")
    print("|---|---|---|---|---|---|---|")
    for r in runs:
        p = r["peaks"]
        print(f"| {r['run']} | " + " | ".join(cell(p[k], "{:.1f}") for k in p) + " | |")
    print()
    print("At the highest record of the fixed-area q:")
    print()
    print("| run | eps_a % | q/p platen | q/p corrected (V/h, sigma3_balls) | q/p Love-Weber | "
          "F/A_platen over F/A_rc | membrane adds kPa (measured / thin shell) | q_net kPa |")
    print("|---|---|---|---|---|---|---|---|")
    for r in runs:
        if r["periodic"]:
            print(f"| {r['run']} (periodic) | {r['eps']:.2f} | {r['qp_platen']:.3f} | - | {r['qp_platen']:.3f} "
                  "| - | - | - |")
            continue
        print(f"| {r['run']} | {r['eps']:.2f} | {r['qp_platen']:.3f} | {r['qp_corrected']:.3f} | {r['qp_lw']:.3f} "
              f"| {r['area_ratio']:.3f} | {r['membrane_kPa']:.1f} / {r['hoop_kPa']:.1f} | {r['q_net']:.1f} |")


if __name__ == "__main__":
    main()
