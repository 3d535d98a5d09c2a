#!/usr/bin/python3
"""The identification sweep's tables under the identification decision rule (docs/calibration.md, The identification
rate): the rate's denominator is the identifiable cases, those whose hidden extension, fitted freely, passes both
tests of the verdict (the CSV's `data_show`); the goal is all of those named, no wrong name anywhere, and no false
alarm on the null cases, whose own largest gains check the threshold the verdict uses.

    tools/sweep_table.py --level lab=data/sweeps/a.csv,data/sweeps/b.csv --level precise=data/sweeps/c.csv

Reads the CSVs of perf/hidden_sweep (one row per case). A case (hidden, seed) given in more than one file of a
level is taken from the last file named, and the table says so. Prints Markdown: per level, the rate with its
counts, the wrong names, the identifiable cases the generic rival took (with its shape and gains where the sweep
wrote them), the false alarms and the null statistic (per null case, the largest over the extensions
of the smaller of its BIC gain and held-out gain: what would have to reach the threshold for a false alarm);
then the detection power per extension and level (the strengths named right, those the data show but were not
named, and those the data do not show).
"""
import argparse
import math
import sys

from _csv_rows import read_rows

THRESHOLD = 6.0  # host/fit/diagnose.hpp kStrongEvidence: BIC and held-out chi2 both lower by at least this


def first_name(verdict):
    return verdict.split(" ")[0] if verdict else "none"


def extensions(row):
    return [k[: -len("_bic_gain")] for k in row if k.endswith("_bic_gain")]


def null_statistic(row):
    """The largest over the extensions of min(BIC gain, held-out gain) of a null case."""
    best = -math.inf
    base_heldout = float(row["base_heldout"])
    for e in extensions(row):
        bic, held = row.get(e + "_bic_gain", ""), row.get(e + "_heldout", "")
        if bic in ("", None) or held in ("", None):
            continue
        best = max(best, min(float(bic), base_heldout - float(held)))
    return best


def rival_text(row):
    """A case the rival took: the hidden extension's gains against the base model, and the rival's."""
    h = row["hidden"]
    text = (f"; {h} {row['strength']} (seed {row['seed']}): BIC gain {float(row[h + '_bic_gain']):.1f}, held-out chi2 "
            f"{float(row['base_heldout']):.1f} -> {float(row[h + '_heldout']):.1f}")
    if not row.get("rival_shape"):
        return text + ", the rival not recorded (a row from before the sweep wrote it)"
    return text + (f", the rival {row['rival_shape']}: BIC gain {float(row['rival_gain']):.1f}, held-out chi2 "
                   f"{float(row['rival_heldout']):.1f}")


def load_level(paths):
    cases, repeated = {}, []
    for path in paths:
        for r in read_rows(path):
            key = (r["hidden"], int(r["seed"]))
            if key in cases:
                repeated.append(f"{key[0]} seed {key[1]}")
            cases[key] = r
    return cases, repeated


def quantile(values, q):
    v = sorted(values)
    if not v:
        return math.nan
    pos = q * (len(v) - 1)
    lo = int(math.floor(pos))
    hi = min(lo + 1, len(v) - 1)
    return v[lo] + (v[hi] - v[lo]) * (pos - lo)


def summary(name, cases, repeated):
    nulls = [r for (h, _), r in cases.items() if h == "none"]
    hidden = [r for (h, _), r in cases.items() if h != "none"]
    identifiable = [r for r in hidden if r.get("data_show") == "1"]
    named = [r for r in identifiable if first_name(r["verdict"]) == r["hidden"]]
    wrong = [r for r in hidden if first_name(r["verdict"]) not in ("none", r["hidden"])]
    alarms = [r for r in nulls if first_name(r["verdict"]) != "none"]
    stats = [null_statistic(r) for r in nulls]
    out = [f"### {name}", ""]
    out.append(f"- identifiable cases named right: **{len(named)} of {len(identifiable)}** "
               f"({len(hidden)} cases with an effect hidden, {len(hidden) - len(identifiable)} of them not shown by "
               "their data)")
    out.append(f"- wrong names: {len(wrong)}" +
               "".join(f"; {r['hidden']} {r['strength']} (seed {r['seed']}) named {r['verdict']}" for r in wrong))
    bound = 1 - 0.05 ** (1 / len(nulls)) if nulls else math.nan
    out.append(f"- false alarms: **{len(alarms)} of {len(nulls)}** null cases" +
               "".join(f"; seed {r['seed']} named {r['verdict']}" for r in alarms) +
               (f" (with none, the false-alarm rate is below {100 * bound:.0f}% at 95% confidence)" if not alarms and
                nulls else ""))
    taken = [r for r in identifiable if first_name(r["verdict"]) == "none"]
    out.append(f"- identifiable cases the generic rival took (the effect shown against the base model, not against the "
               f"best generic discrepancy): {len(taken)}" + "".join(rival_text(r) for r in taken))
    if stats:
        out.append(f"- null statistic (largest min(BIC gain, held-out gain) over the extensions): median "
                   f"{quantile(stats, 0.5):.1f}, 90% {quantile(stats, 0.9):.1f}, largest {max(stats):.1f}, against "
                   f"the threshold {THRESHOLD:g}; {sum(s >= THRESHOLD for s in stats)} of {len(stats)} reach it")
    if repeated:
        out.append(f"- {len(repeated)} cases given in more than one file, the last file's taken")
    return out, hidden


def power(levels):
    names = sorted({r["hidden"] for _, hidden in levels for r in hidden})
    out = ["| hidden | " + " | ".join(f"{n}: named | {n}: shown, missed | {n}: not shown" for n, _ in levels) + " |",
           "|---|" + "---|---|---|" * len(levels)]
    for e in names:
        cells = []
        for _, hidden in levels:
            rows = sorted((r for r in hidden if r["hidden"] == e), key=lambda r: float(r["strength"]))
            found = [r["strength"] for r in rows if r.get("data_show") == "1" and first_name(r["verdict"]) == e]
            missed = [r["strength"] for r in rows if r.get("data_show") == "1" and first_name(r["verdict"]) != e]
            unseen = [r["strength"] for r in rows if r.get("data_show") != "1"]
            cells += [", ".join(found) or "-", ", ".join(missed) or "-", ", ".join(unseen) or "-"]
        out.append(f"| {e} | " + " | ".join(cells) + " |")
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--level", action="append", required=True, metavar="NAME=CSV[,CSV...]",
                    help="a noise level's name and its sweep files")
    args = ap.parse_args()
    lines, levels = ["## The identification rate under the decision rule", ""], []
    for spec in args.level:
        if "=" not in spec:
            sys.exit(f"sweep_table: --level {spec}: give NAME=CSV[,CSV...]")
        name, files = spec.split("=", 1)
        cases, repeated = load_level([f for f in files.split(",") if f])
        if not cases:
            sys.exit(f"sweep_table: --level {name}: no cases in {files}")
        text, hidden = summary(name, cases, repeated)
        lines += text + [""]
        levels.append((name, hidden))
    lines += ["### Detection power (strengths per extension)", ""] + power(levels)
    print("\n".join(lines))


if __name__ == "__main__":
    main()
