#!/usr/bin/env python3
"""The bytes a particle-step moves on a GPU, from Nsight Compute's CSV of the step kernels (perf/device_check.sh's
bytes stage, issue 64 item 2): per kernel its launches, the DRAM bytes read and written per launch and ball, its time
and the bandwidth it reached, and the sum of a step (a step launches the ball-force kernel once). The CPU's count
(perf/instruction_count.sh BYTES=1) is of cache lines brought in, write-allocate fills included; here reads and
writes are apart, and the device's 32-byte sectors and its L2 cache decide what reaches memory.
  tools/ncu_bytes.py NCU_CSV BALLS        # NCU_CSV: ncu --csv --print-units base --metrics
                                          #   dram__bytes_read.sum,dram__bytes_write.sum,gpu__time_duration.sum
"""
import csv
import re
import sys
from collections import defaultdict

METRICS = {"dram__bytes_read.sum": "read", "dram__bytes_write.sum": "write", "gpu__time_duration.sum": "ns"}
# ncu scales its units unless told --print-units base; both are read.
SCALE = {"byte": 1, "kbyte": 1e3, "mbyte": 1e6, "gbyte": 1e9, "b": 1, "kb": 1e3, "mb": 1e6, "gb": 1e9,
         "nsecond": 1, "usecond": 1e3, "msecond": 1e6, "second": 1e9, "ns": 1, "us": 1e3, "ms": 1e6, "s": 1e9}
STEP_KERNEL = "BallForce"


def first_argument(text):
    """The first template argument of the text that follows a '<': up to the first ',' or '>' at its own depth."""
    depth = 0
    for i, c in enumerate(text):
        if c == "<":
            depth += 1
        elif c in ",>" and depth == 0:
            return text[:i]
        elif c == ">":
            depth -= 1
    return text


def short_name(kernel):
    """The triaxdem functor a Kokkos kernel runs, namespaces left out: the first template argument of Kokkos'
    ParallelFor/Reduce/Scan (inside Kokkos 4's CombinedFunctorReducer where there is one), and of a reduction tree's
    level the functor it sums and its blocks (TreeLevel<Leapfrog, EvenBlocks>). ncu's demangled names drop some
    namespaces and write an anonymous one as <unnamed> (seen on an H200 with Kokkos 3.4)."""
    name = re.sub(r"(?<=<)<?unnamed>::|\(anonymous namespace\)::", "", kernel)
    m = re.search(r"Parallel(?:For|Reduce|Scan)<(?:[\w:]*CombinedFunctorReducer<)?(.*)", name)
    if not m:
        return kernel[:60]
    functor = re.sub(r"\b\w+::", "", first_argument(m.group(1)))
    return re.sub(r"<(\s*\d+\s*,\s*)+", "<", functor)


def read(path):
    """{launch id: (kernel, {read, write, ns})} from ncu's CSV (its own lines only: those that start with a quote)."""
    lines = [line for line in open(path) if line.startswith('"')]
    launches = {}
    for row in csv.DictReader(lines):
        what = METRICS.get(row.get("Metric Name", ""))
        if what is None:
            continue
        unit = row.get("Metric Unit", "").strip().lower()
        if unit not in SCALE:
            sys.exit("ncu_bytes: %s: unit %r of %s not known" % (path, unit, row["Metric Name"]))
        value = float(row["Metric Value"].replace(",", "")) * SCALE[unit]
        kernel, values = launches.setdefault(row["ID"], (short_name(row["Kernel Name"]), {}))
        values[what] = value
    return launches


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    path, balls = sys.argv[1], int(sys.argv[2])
    launches = read(path)
    if not launches:
        sys.exit("ncu_bytes: %s holds no metric of %s (did ncu read the counters?)" % (path, ", ".join(METRICS)))
    per = defaultdict(lambda: defaultdict(float))
    for kernel, values in launches.values():
        per[kernel]["launches"] += 1
        for what in METRICS.values():
            per[kernel][what] += values.get(what, 0.0)
    steps = per[STEP_KERNEL]["launches"] if STEP_KERNEL in per else 0
    print("| kernel | launches | read bytes/ball | written bytes/ball | us a launch | GB/s |")
    print("|---|---|---|---|---|---|")
    total = {"read": 0.0, "write": 0.0, "ns": 0.0}
    for kernel, s in sorted(per.items(), key=lambda kv: -kv[1]["read"] - kv[1]["write"]):
        n = s["launches"]
        print("| %s | %d | %.0f | %.0f | %.1f | %.0f |" % (
            kernel, n, s["read"] / n / balls, s["write"] / n / balls, s["ns"] / n / 1e3,
            (s["read"] + s["write"]) / s["ns"] if s["ns"] > 0 else float("nan")))
        for what in total:
            total[what] += s[what]
    if steps:
        print("\na particle-step (%d steps of %d balls): %.0f bytes read, %.0f written, %.2f ns in these kernels, "
              "%.0f GB/s" % (steps, balls, total["read"] / steps / balls, total["write"] / steps / balls,
                             total["ns"] / steps / balls, (total["read"] + total["write"]) / total["ns"]))
    else:
        print("\nno %s launch among them: no step to count per" % STEP_KERNEL)


if __name__ == "__main__":
    main()
