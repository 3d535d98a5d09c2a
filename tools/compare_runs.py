#!/usr/bin/env python3
"""How far two runs of the same job lie apart: a CPU and a GPU run, two thread counts, two builds.

For each CSV file the two run folders share (series.csv, summary.csv, ...) it compares every numeric column
row by row, and for checkpoint.h5 (read with h5py where installed) every numeric dataset. A file is 'identical'
when every value is equal as written (CSV: the text; HDF5: the bits); otherwise it gives the largest relative
difference, |a - b| / max(|a|, |b|, floor), with the column and row where it occurs. The floor (default 1e-12)
keeps values that are zero in one run from dividing by zero. What says where and how long a run ran, not what it
computed, is left out: wall-clock times (wall_s, a checkpoint's stage_times_s, timings.csv, pools.csv) and the build and machine
(version, backend, config: a CSV column or an HDF5 dataset whose name ends in an ignored name).

    tools/compare_runs.py RUN_A RUN_B [--tolerance 1e-9] [--floor 1e-12] [--ignore wall_s,...]

Exit status 0 when every compared value agrees within the tolerance (0 asks for identical), 1 when one does not,
2 when there is nothing to compare.
"""
import argparse
import csv
import math
import os
import sys


def read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(line for line in f if not line.startswith("#")))
    return (rows[0], rows[1:]) if rows else ([], [])


def relative(a, b, floor):
    if a == b or (math.isnan(a) and math.isnan(b)):
        return 0.0
    if math.isnan(a) or math.isnan(b) or math.isinf(a) or math.isinf(b):
        return math.inf
    return abs(a - b) / max(abs(a), abs(b), floor)


class Worst:
    """The largest difference seen in one file, and where."""

    def __init__(self):
        self.value, self.where, self.unequal, self.count = 0.0, "", 0, 0


def compare_csv(path_a, path_b, floor, ignore):
    head_a, rows_a = read_csv(path_a)
    head_b, rows_b = read_csv(path_b)
    notes, worst = [], Worst()
    if head_a != head_b:
        notes.append("columns differ")
    if len(rows_a) != len(rows_b):
        notes.append(f"{len(rows_a)} rows against {len(rows_b)}")
    shared = [c for c in head_a if c in head_b and c not in ignore]
    for r, (ra, rb) in enumerate(zip(rows_a, rows_b)):
        for c in shared:
            ta, tb = ra[head_a.index(c)], rb[head_b.index(c)]
            try:
                a, b = float(ta), float(tb)
            except ValueError:
                if ta != tb:
                    notes.append(f"text of '{c}' differs in row {r + 1}")
                continue
            worst.count += 1
            if ta != tb:
                worst.unequal += 1
                d = relative(a, b, floor)
                if d > worst.value:
                    worst.value, worst.where = d, f"column {c}, row {r + 1}"
    return worst, notes


def compare_h5(path_a, path_b, floor, ignore):
    import numpy as np
    import h5py

    worst, notes = Worst(), []
    with h5py.File(path_a, "r") as fa, h5py.File(path_b, "r") as fb:
        names = []
        fa.visititems(lambda n, o: names.append(n) if isinstance(o, h5py.Dataset) else None)
        for n in names:
            if any(n.endswith(i) for i in ignore):
                continue
            if n not in fb:
                notes.append(f"{n} only in the first")
                continue
            a, b = fa[n][()], fb[n][()]
            if not (np.issubdtype(np.asarray(a).dtype, np.number) and np.issubdtype(np.asarray(b).dtype, np.number)):
                continue
            a, b = np.asarray(a, dtype=float).ravel(), np.asarray(b, dtype=float).ravel()
            if a.shape != b.shape:
                notes.append(f"{n}: {a.size} values against {b.size}")
                continue
            worst.count += a.size
            neq = ~((a == b) | (np.isnan(a) & np.isnan(b)))
            worst.unequal += int(neq.sum())
            if neq.any():
                d = np.abs(a - b) / np.maximum(np.maximum(np.abs(a), np.abs(b)), floor)
                d[~np.isfinite(d) & neq] = np.inf
                k = int(np.argmax(np.where(neq, d, 0.0)))
                if d[k] > worst.value:
                    worst.value, worst.where = float(d[k]), f"{n}[{k}]"
    return worst, notes


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("run_a")
    ap.add_argument("run_b")
    ap.add_argument("--tolerance", type=float, default=0.0, help="largest relative difference allowed (0: identical)")
    ap.add_argument("--floor", type=float, default=1e-12, help="denominator floor of the relative difference")
    ignored = "wall_s,stage_times_s,version,backend,config"
    ap.add_argument("--ignore", default=ignored, help=f"columns and datasets not compared, comma-separated (default {ignored})")
    args = ap.parse_args()
    ignore = set(args.ignore.split(","))
    for run in (args.run_a, args.run_b):
        if not os.path.isdir(run):
            sys.exit(f"compare_runs: {run}: not a folder")
    # timings.csv and pools.csv say how long each stage and each run took, nothing the job computed.
    files = sorted((set(os.listdir(args.run_a)) & set(os.listdir(args.run_b))) - {"timings.csv", "pools.csv"})
    compared, failed = 0, False
    print(f"| file | values | unequal | largest relative difference | where | notes |\n|---|---|---|---|---|---|")
    for name in files:
        pa, pb = os.path.join(args.run_a, name), os.path.join(args.run_b, name)
        if name.endswith(".csv"):
            worst, notes = compare_csv(pa, pb, args.floor, ignore)
        elif name == "checkpoint.h5":
            try:
                worst, notes = compare_h5(pa, pb, args.floor, ignore)
            except ImportError:
                print(f"| {name} | | | | | not compared: no h5py |")
                continue
        else:
            continue
        compared += 1
        # Every note is a difference of shape (columns, rows, datasets, text), which no tolerance covers.
        failed |= worst.value > args.tolerance or bool(notes)
        verdict = "identical" if worst.unequal == 0 else f"{worst.value:.3g}"
        print(f"| {name} | {worst.count} | {worst.unequal} | {verdict} | {worst.where} | {'; '.join(notes)} |")
    if compared == 0:
        print("compare_runs: no CSV or checkpoint the two folders share", file=sys.stderr)
        sys.exit(2)
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
