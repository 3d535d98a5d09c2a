#!/usr/bin/python3
"""docs/results.md, the results page, made from the committed artifacts and nothing else: each section reads the small
files a run left (under data/), with the command that made them, and prints its table. A figure the README or a
reference doc states belongs here, from its files.

    tools/results_page.py                  # write docs/results.md
    tools/results_page.py --check          # exit 1 where the page differs from what its artifacts give now
    tools/results_page.py --root DIR --page FILE --check    # another copy of the artifacts (the test's)

A changed artifact must change the page, and a changed page without its artifact fails the check (ctest
Docs.ResultsPageIsMadeFromItsArtifacts; tests/scripts_smoke.sh shows it failing on a changed file).
"""
import argparse
import difflib
import io
import os
import statistics
import subprocess
import sys

from _csv_rows import read_rows
import coverage_table

HERE = os.path.dirname(os.path.abspath(__file__))


def fmt(v, digits=3):
    return f"{float(v):.{digits}g}"


def prediction_section(folder, periodic_column):
    """A calibration's prediction beside its data (prediction.csv) and its calibrated values (calibrated.csv)."""
    rows = read_rows(os.path.join(folder, "prediction.csv"))
    cal = read_rows(os.path.join(folder, "calibrated.csv"))
    out = io.StringIO()
    extra = " periodic cell kPa |" if periodic_column else ""
    out.write(f"| sigma3 kPa | measured q_peak kPa | predicted kPa | error |{extra}\n|---|---|---|---|"
              f"{'---|' if periodic_column else ''}\n")
    for r in rows:
        out.write(f"| {r['sigma3_kPa']} | {fmt(r['measured_q_peak_kPa'], 4)} | {fmt(r['predicted_q_peak_kPa'], 4)} | "
                  f"{float(r['error_pct']):+.1f}% |" + (f" {fmt(r['periodic_q_peak_kPa'], 4)} |" if periodic_column else "")
                  + "\n")
    mean = statistics.fmean(abs(float(r["error_pct"])) for r in rows)
    values = "; ".join(f"{c['parameter']} {fmt(c['value'])} [{fmt(c['low95'])}, {fmt(c['high95'])}]" for c in cal)
    out.write(f"\nMean |error| **{mean:.1f}%**, at {values} (chi2 {fmt(cal[0]['chi2'])} on {cal[0]['data']} data, "
              f"{cal[0]['runs']} runs).\n")
    return out.getvalue()


def table6_periodic(root):
    """The periodic cell's S-1 calibration predicting the membrane test (Table 6's S-1)."""
    folder = os.path.join(root, "data/runs/S1_table6_periodic")
    return prediction_section(folder, False), [folder], ("triaxdem calibrate data/tang2025_table6_peak.csv --config "
                                                         "data/runs/S1_table6_periodic/base.toml --material S-1 -j 2")


def walled_on_periodic(root):
    """Another code's walled data (YADE, 4,000 balls) calibrated on the periodic cell, predicted by the walled cell."""
    folder = os.path.join(root, "data/runs/walled_periodic_predict_walls")
    return prediction_section(folder, True), [folder], ("triaxdem calibrate tests/data/crosscode/walled_seed1.csv "
                                                        "--config data/runs/walled_periodic_predict_walls/base.toml "
                                                        "--reference-test periodic --predict walls -j 2")


def identification(root):
    """The diagnosis's identification rate on synthetic data (hidden effects and null cases)."""
    folder = os.path.join(root, "data/sweeps/identification")
    text = subprocess.run([sys.executable, os.path.join(HERE, "sweep_table.py"),
                           "--level", "lab=" + os.path.join(folder, "lab.csv"),
                           "--level", "precise=" + os.path.join(folder, "precise.csv")],
                          check=True, capture_output=True, text=True).stdout
    # The sweep's own title is this section's.
    text = "\n".join(l for l in text.splitlines() if not l.startswith("## The identification rate"))
    return text.strip() + "\n", [folder], "perf/identification_table.sh (tools/sweep_table.py for the table)"


def coverage(root):
    """How often the calibration's 95% intervals hold the parameters that made synthetic data."""
    folder = os.path.join(root, "data/sweeps/coverage")
    rows = []
    for f in sorted(os.listdir(folder)):
        if f.endswith(".csv"):
            rows += read_rows(os.path.join(folder, f))
    out = io.StringIO()
    coverage_table.table(rows, out)
    return out.getvalue(), [folder], ('perf/coverage.sh (METHOD=ensemble with the binary of its commit; '
                                      'METHOD=rescatter_max at 9827c3e; METHOD=specimens at 82f074b, cases 17-30 of 1x at ac9b891 and fb5505c, the same code as b79c38d), '
                                      'tools/coverage_table.py data/sweeps/coverage')


SECTIONS = [
    ("Table 6, S-1, calibrated on the periodic cell and predicted by the membrane test", table6_periodic),
    ("Another code's walled data, calibrated on the periodic cell and predicted between walls", walled_on_periodic),
    ("The diagnosis: hidden effects named, and false alarms", identification),
    ("Coverage of the 95% intervals", coverage),
]


def page(root):
    out = io.StringIO()
    out.write("# Results\n\n<!-- Made by tools/results_page.py from the files each section names: edit those, not this "
              "page (ctest Docs.ResultsPageIsMadeFromItsArtifacts fails where they differ). -->\n\n"
              "Every figure below is read from committed files; each section names them and the command that made "
              "them. The reference docs explain the methods; this page holds their results.\n")
    for title, make in SECTIONS:
        text, folders, command = make(root)
        where = ", ".join("`" + os.path.relpath(f, root) + "`" for f in folders)
        out.write(f"\n## {title}\n\n{(make.__doc__ or '').strip()} From {where}; made by `{command}`.\n\n{text}")
    return out.getvalue()


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--root", default=os.path.dirname(HERE), help="the repository (or a copy of its data/)")
    ap.add_argument("--page", help="the page (default ROOT/docs/results.md)")
    ap.add_argument("--check", action="store_true", help="compare, write nothing; exit 1 on a difference")
    a = ap.parse_args()
    path = a.page or os.path.join(a.root, "docs", "results.md")
    text = page(a.root)
    if a.check:
        old = open(path).read() if os.path.exists(path) else ""
        if old != text:
            sys.stdout.writelines(difflib.unified_diff(old.splitlines(True), text.splitlines(True), path, "artifacts"))
            sys.exit(f"results_page: {path} is not what its artifacts give: run tools/results_page.py and commit both")
        print(f"results_page: {path} matches its artifacts")
        return
    with open(path, "w") as f:
        f.write(text)
    print(f"results_page: wrote {path}")


if __name__ == "__main__":
    main()
