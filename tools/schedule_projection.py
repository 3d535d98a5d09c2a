#!/usr/bin/env python3
"""A job's wall time on R MPI ranks, projected from the run times it measured (pools.csv).

Every job that runs process pools (study, calibrate, diagnose, perf/hidden_sweep) writes pools.csv: each pool's
pieces and their run times, and the job's wall time. Spread over R ranks (host/util/ranks.hpp), the leader hands the
pieces to the R - 1 others, longest first, one at a time each; between the pools every rank does the same serial
work (fits, reports), which more ranks do not shorten. So the projection is

    wall(R) = serial + sum over pools of the longest-first schedule of its pieces on R - 1 ranks,
    serial  = the job's wall time - the pools' wall times (as measured),

and the efficiency is the pieces' run time summed over (R - 1) x the pools' projected time. The same schedule at the
measured worker count is printed beside the measured wall time: the model's own check.

    tools/schedule_projection.py POOLS_CSV [--ranks 64,512] [--time-scale F] [--piece-scale K] [--label TEXT]

--time-scale multiplies every run time (a cell of 1,920 balls against one of 200: about 9.6, the runs' steps being
the same at one inertial number); --piece-scale repeats every pool's pieces K times (an ensemble of 16 against one of
4: 4). Both are stated models, not measurements: the output says which were used.
"""
import argparse
import csv
import heapq
import sys


def read_pools(path):
    with open(path, newline="") as f:
        first = f.readline()
        if "job_wall_s" not in first:
            sys.exit(f"schedule_projection: {path}: not a pools.csv (its first line names job_wall_s)")
        job_wall = float(first.split("job_wall_s")[1].split()[0])
        pools = {}
        for row in csv.DictReader(line for line in f if not line.startswith("#")):
            p = pools.setdefault(int(row["pool"]), {"what": row["what"], "workers": int(row["workers"]),
                                                    "wall": float(row["pool_wall_s"]), "pieces": []})
            p["pieces"].append(float(row["seconds"]))
    return job_wall, [pools[k] for k in sorted(pools)]


def longest_first(pieces, workers):
    """The makespan of the pieces on `workers`, each taking the longest piece left as it comes free."""
    if not pieces:
        return 0.0
    free = [0.0] * max(1, workers)
    for t in sorted(pieces, reverse=True):
        heapq.heappush(free, heapq.heappop(free) + t)
    return max(free)


def project(job_wall, pools, workers, time_scale=1.0, piece_scale=1):
    serial = max(0.0, job_wall - sum(p["wall"] for p in pools))
    span = 0.0
    work = 0.0
    for p in pools:
        pieces = [t * time_scale for t in p["pieces"]] * piece_scale
        span += longest_first(pieces, workers)
        work += sum(pieces)
    return serial, span, work


def fmt(s):
    h, rest = divmod(int(round(s)), 3600)
    m, sec = divmod(rest, 60)
    return f"{h} h {m:02d} min" if h else f"{m} min {sec:02d} s"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("pools")
    ap.add_argument("--ranks", default="64,512", help="rank counts to project (comma-separated)")
    ap.add_argument("--time-scale", type=float, default=1.0)
    ap.add_argument("--piece-scale", type=int, default=1)
    ap.add_argument("--label", default="")
    a = ap.parse_args()
    job_wall, pools = read_pools(a.pools)
    label = a.label or a.pools
    npieces = sum(len(p["pieces"]) for p in pools)
    print(f"{label}: {len(pools)} pools, {npieces} pieces, the job {fmt(job_wall)} as measured")
    measured_workers = max((p["workers"] for p in pools), default=1)
    serial, span, work = project(job_wall, pools, measured_workers)
    print(f"  check at the measured {measured_workers} workers: {fmt(serial + span)} projected "
          f"(serial {fmt(serial)} + pools {fmt(span)}) against {fmt(job_wall)} measured")
    if a.time_scale != 1 or a.piece_scale != 1:
        print(f"  model: run times x {a.time_scale:g}, pieces per pool x {a.piece_scale} (stated, not measured)")
    print("  ranks | projected wall | serial | pools | efficiency of the working ranks")
    for r in [int(x) for x in a.ranks.split(",") if x]:
        s, sp, w = project(job_wall, pools, max(1, r - 1), a.time_scale, a.piece_scale)
        eff = w / (max(1, r - 1) * sp) if sp > 0 else 1.0
        print(f"  {r:5d} | {fmt(s + sp):>14} | {fmt(s):>9} | {fmt(sp):>11} | {100 * eff:5.1f}%")


if __name__ == "__main__":
    main()
