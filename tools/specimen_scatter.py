#!/usr/bin/python3
"""Scatter of periodic cells against their size, from the runs of perf/specimen_scatter.sh: per pressure and size,
the void ratio after consolidation, the mean of q / sigma3 and of eps_v across the specimens at a few strains
(each read as a mean over +-min(30%, 0.25%) of strain, as the misfit reads a curve) with its standard error, their
standard deviation, then the exponent a of sd ~ N^-a from the smallest cell to each larger one, and the difference
of the means between successive sizes with its standard error: how the finite-cell bias falls with size (host/
cell_bias.hpp takes N^-1/2, under which each step of 4 halves the difference)."""
import glob
import math
import os
import statistics
import sys

from plot_triaxial import read_series

STRAINS = [0.05, 0.2, 0.5, 1, 2, 3, 4, 6, 8]  # percent


def at(eps, values, strain):
    half = min(0.3 * strain, 0.25)
    inside = [v for e, v in zip(eps, values) if abs(e - strain) < half]
    return statistics.fmean(inside) if inside else math.nan


def main(work):
    sd, voids, means = {}, {}, {}
    for folder in sorted(glob.glob(os.path.join(work, "n*_*_*"))):
        if not os.path.isdir(folder):
            continue
        n, s3, _ = os.path.basename(folder)[1:].split("_")
        _, s = read_series(folder)
        eps, q, ev, e0 = s["eps_a_pct"], s["q_kPa"], s["eps_v_pct"], s["void_ratio"][0]
        voids.setdefault((int(s3), int(n)), []).append(e0)
        sd.setdefault((int(s3), int(n)), []).append(
            ([at(eps, q, s) / float(s3) for s in STRAINS], [at(eps, ev, s) for s in STRAINS]))
    print("strain (%):" + "".join(f"{s:7g}" for s in STRAINS))
    spread = {}
    for (s3, n), runs in sorted(sd.items()):
        print(f"{s3:4d} kPa {n:5d} balls ({len(runs)}) void ratio {statistics.fmean(voids[(s3, n)]):.4f}")
        for k, name in ((0, "q/s3"), (1, "eps_v %")):
            cols = list(zip(*(r[k] for r in runs)))
            spread[(s3, n, k)] = [statistics.stdev(c) if len(c) > 1 else math.nan for c in cols]
            means[(s3, n, k)] = ([statistics.fmean(c) for c in cols], [v / math.sqrt(len(runs)) for v in spread[(s3, n, k)]])
            print(f"{s3:4d} kPa {n:5d} balls mean {name:8s}" + "".join(f"{statistics.fmean(c):7.3f}" for c in cols))
            print(f"{s3:4d} kPa {n:5d} balls s.e. {name:8s}" +
                  "".join(f"{v / math.sqrt(len(runs)):7.3f}" for v in spread[(s3, n, k)]))
            print(f"{s3:4d} kPa {n:5d} balls ({len(runs)}) sd {name:8s}" +
                  "".join(f"{v:7.3f}" for v in spread[(s3, n, k)]))
    print("exponent a of sd ~ N^-a")
    for (s3, n, k) in sorted(spread):
        small = min(m for (p, m, _) in spread if p == s3)
        if n == small:
            continue
        a = [math.log(x / y) / math.log(n / small) if x > 0 and y > 0 else math.nan
             for x, y in zip(spread[(s3, small, k)], spread[(s3, n, k)])]
        print(f"{s3:4d} kPa {small}->{n} {'q/s3' if k == 0 else 'eps_v':6s}" + "".join(f"{v:7.2f}" for v in a))

    print("difference of the means between successive sizes (smaller - larger), and its standard error")
    for (s3, n, k) in sorted(means):
        larger = sorted(m for (p, m, j) in means if p == s3 and j == k and m > n)
        if not larger:
            continue
        (a, sa), (b, sb) = means[(s3, n, k)], means[(s3, larger[0], k)]
        print(f"{s3:4d} kPa {n}-{larger[0]} {'q/s3' if k == 0 else 'eps_v %':7s}" +
              "".join(f"{x - y:7.3f}" for x, y in zip(a, b)))
        print(f"{s3:4d} kPa {n}-{larger[0]} {'s.e.':7s}" +
              "".join(f"{math.hypot(x, y):7.3f}" for x, y in zip(sa, sb)))


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "runs/specimen_scatter")
