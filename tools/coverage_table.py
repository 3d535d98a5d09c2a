#!/usr/bin/python3
"""The coverage table of the calibration's 95% intervals (perf/coverage.sh): per method and data size, how many cases
each marginal 95% interval and the joint 95% region held the values that made the data, the chance of so few under a
true 95% (binomial), the median widths, and on which side the misses fell.

    tools/coverage_table.py data/sweeps/coverage [--method ensemble]

Reads OUT/<method>.csv (one row a case and size). The joint region holds the truth where the surrogate chi2's rise there
is at most the region's (`region_rise` <= 1). `truth_chi2` is the truth run on the calibration's own ensemble: its rise
over the best run, set against the misfit model's region (chi2_95(2) x max(1, chi2 / (data - 2))), tells a model noise
too narrow for the data (the run's rise is large too) from a surrogate that misplaces the region (the run's rise is
small). The widths are set against the ensemble method's (today's, before issue 85) on the cases both have.
Prints Markdown.
"""
import argparse
import math
import os
import statistics
import sys

from _csv_rows import read_rows

CHI2_95_2 = 5.991  # host/fit/calibrate.cpp chi2_95(2)


def binom_cdf(k, n, p):
    """P(X <= k) for X ~ Binomial(n, p)."""
    return sum(math.comb(n, j) * p ** j * (1 - p) ** (n - j) for j in range(k + 1))


def num(row, key):
    v = row.get(key, "")
    return float(v) if v not in ("", None) else math.nan


def side(truth, lo, hi):
    return "below" if truth < lo else "above" if truth > hi else "inside"


def width(r, p):
    return num(r, p + "_hi") - num(r, p + "_lo")


def against(g, base):
    """The median widths of g's rows over those of `base` (rows of the same size), on the cases both have."""
    if not base:
        return "-"
    by_case = {r["case"]: r for r in base}
    common = [r for r in g if r["case"] in by_case]
    if not common:
        return "-"
    ratio = []
    for p in ("mu_s", "mu_r"):
        b = statistics.median(width(by_case[r["case"]], p) for r in common)
        ratio.append(statistics.median(width(r, p) for r in common) / b if b > 0 else math.nan)
    return f"{ratio[0]:.2f} / {ratio[1]:.2f} ({len(common)} case{'s' if len(common) > 1 else ''})"


def table(rows, out, reference="ensemble"):
    groups = {}
    for r in rows:
        groups.setdefault((r["method"], int(r["size"])), []).append(r)
    out.write("| method | data size | cases | mu_s interval holds | mu_r interval holds | joint region holds | "
              "P(so few) joint | median width mu_s | median width mu_r | widths over " + reference + "'s, same cases "
              "(mu_s / mu_r) | mu_s misses (below/above) | truth run inside the model region's rise | median runs a fit | "
              "commits |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n")
    for (method, size), g in sorted(groups.items()):
        n = len(g)
        held = {}
        for p in ("mu_s", "mu_r"):
            held[p] = sum(side(num(r, p + "_true"), num(r, p + "_lo"), num(r, p + "_hi")) == "inside" for r in g)
        joint = sum(num(r, "region_rise") <= 1 for r in g)
        below = sum(side(num(r, "mu_s_true"), num(r, "mu_s_lo"), num(r, "mu_s_hi")) == "below" for r in g)
        above = sum(side(num(r, "mu_s_true"), num(r, "mu_s_lo"), num(r, "mu_s_hi")) == "above" for r in g)
        run_in, run_n = 0, 0
        for r in g:
            t, c, d = num(r, "truth_chi2"), num(r, "chi2"), num(r, "data")
            if math.isfinite(t):
                run_n += 1
                run_in += t - c <= CHI2_95_2 * max(1.0, c / max(1.0, d - 2))
        w_s = statistics.median(width(r, "mu_s") for r in g)
        w_r = statistics.median(width(r, "mu_r") for r in g)
        ratio = against(g, groups.get((reference, size), []))
        commits = ", ".join(sorted({r["commit"] for r in g}))
        runs = statistics.median(num(r, "runs") for r in g)
        out.write(f"| {method} | {size}x the cell's balls | {n} | {held['mu_s']} of {n} | {held['mu_r']} of {n} | "
                  f"{joint} of {n} | {binom_cdf(joint, n, 0.95):.2g} | {w_s:.3g} | {w_r:.3g} | {ratio} | {below}/{above} | "
                  f"{run_in} of {run_n} | {runs:.0f} | {commits} |\n")
    out.write("\nA true 95% interval holds the truth in 27 to 30 of 30 cases (it misses about 1.5 times in 30); "
              "P(so few) is the chance of at most the joint count under a true 95%. The truth's run is set against the "
              "region the misfit's model gives (chi2_95(2) x max(1, chi2 / (data - 2))), not the one measured on the "
              "specimens: where it lies above that rise, the model's noise was too narrow for these data.\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("folder", help="perf/coverage.sh's OUT (one <method>.csv a method)")
    ap.add_argument("--method", help="only this method's rows")
    a = ap.parse_args()
    files = sorted(f for f in os.listdir(a.folder) if f.endswith(".csv")) if os.path.isdir(a.folder) else []
    if not files:
        sys.exit(f"coverage_table: no <method>.csv in {a.folder}")
    rows = []
    for f in files:
        rows += [r for r in read_rows(os.path.join(a.folder, f)) if not a.method or r["method"] == a.method]
    if not rows:
        print("coverage_table: no cases yet")
        return
    table(rows, sys.stdout)


if __name__ == "__main__":
    main()
