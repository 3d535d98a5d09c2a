#!/usr/bin/python3
"""The peak-strength table of a study, as the docs show it, made from the study's files rather than typed.

    tools/docs_table.py out/small                                   # print the Markdown table
    tools/docs_table.py out/small --doc docs/performance.md --block small   # replace the block in the doc

Reads STUDY/study_summary.csv (`triaxdem study ... --compare LAB.csv --compare PFC.csv`): one row per case with
its q_peak (the peak of the moving mean) and each compared file's q_peak. The highest single record of q, in
brackets, comes from the case's series.csv. The first compared file is the one errors are taken against.
With --doc, the lines between `<!-- docs_table BLOCK -->` and `<!-- /docs_table BLOCK -->` are replaced and the
rest of the file is left as it is; a doc without the markers is refused, not appended to.
"""
import argparse
import math
import os
import sys

from _csv_rows import read_rows


def highest_record(study, case):
    path = os.path.join(study, case, "series.csv")
    if not os.path.exists(path):
        return math.nan
    q = [float(r["q_kPa"]) for r in read_rows(path) if r.get("q_kPa") not in (None, "")]
    return max(q) if q else math.nan


def table(study):
    rows = read_rows(os.path.join(study, "study_summary.csv"))
    if not rows:
        sys.exit(f"docs_table: {study}/study_summary.csv has no cases")
    # Each compared file has a q_peak_<stem>_kPa and an error_<stem>_pct column.
    compared = [c[len("error_"):-len("_pct")] for c in rows[0] if c.startswith("error_") and c.endswith("_pct")]
    head = ["case"] + [f"{c} q_peak (kPa)" for c in compared] + ["triaxdem q_peak (kPa), highest record"]
    if compared:
        head.append(f"vs {compared[0]}")
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    errors = []
    for r in rows:
        if r["status"] != "ok":
            lines.append(f"| {r['case']} | " + " | ".join([""] * (len(head) - 2)) + f" | {r['status']} |")
            continue
        cells = [r["case"]] + [r[f"q_peak_{c}_kPa"] for c in compared]
        cells.append(f"{float(r['q_peak_kPa']):.1f} ({highest_record(study, r['case']):.1f})")
        if compared:
            err = r[f"error_{compared[0]}_pct"]  # empty where the file has no test of the case
            if err:
                errors.append(abs(float(err)))
            cells.append(f"{float(err):+.1f}%" if err else "")
        lines.append("| " + " | ".join(cells) + " |")
    if errors:
        lines.append("")
        lines.append(f"Mean |error| against {compared[0]}: {sum(errors) / len(errors):.1f}%, at most "
                     f"{max(errors):.1f}% ({len(errors)} cases; `tools/docs_table.py {study}`).")
    return "\n".join(lines) + "\n"


def replace_block(doc, block, text):
    begin, end = f"<!-- docs_table {block} -->", f"<!-- /docs_table {block} -->"
    with open(doc) as f:
        content = f.read()
    i, j = content.find(begin), content.find(end)
    if i < 0 or j < i:
        sys.exit(f"docs_table: {doc} has no block '{begin}' ... '{end}' to replace")
    content = content[: i + len(begin)] + "\n" + text + content[j:]
    tmp = doc + ".tmp"
    with open(tmp, "w") as f:
        f.write(content)
    os.replace(tmp, doc)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("study", help="a study's output folder (study_summary.csv)")
    ap.add_argument("--doc", help="a Markdown file whose block to replace")
    ap.add_argument("--block", default="study", help="the block's name (default study)")
    args = ap.parse_args()
    text = table(args.study)
    if args.doc:
        replace_block(args.doc, args.block, text)
        print(f"docs_table: {args.doc}: block {args.block} replaced from {args.study}")
    else:
        sys.stdout.write(text)


if __name__ == "__main__":
    main()
