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
    v = float(v)
    return f"{0.0 if abs(v) < 1e-12 else v:.{digits}g}"  # a bound's rounding (mu_r 1e-19) reads as the 0 it is


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


def table6_loop(root):
    """Table 6 by the loop (perf/table6_loop.sh): each material calibrated on the periodic cell with two fidelities to
    their fixed point (the small membrane specimen, an ensemble of 4) and its pressures predicted by the membrane test,
    then each pressure held out in turn (fitted on the other two, predicted). A case not run yet says so; the loop goes on
    across sittings."""
    folder = os.path.join(root, "data/results/table6_loop")
    out = io.StringIO()
    out.write("| material | fitted | sigma3 kPa: error (held out in bold) | calibrated (95% intervals) | runs | time | "
              "commit |\n|---|---|---|---|---|---|---|\n")
    fitted_errors, held_errors = [], []
    for m in ("S-1", "S-2", "S-3"):
        for c in ("all", "100", "200", "300"):
            case = os.path.join(folder, f"{m}_{'all' if c == 'all' else 'hold' + c}")
            label = "all" if c == "all" else f"all but {c} kPa"
            if not os.path.isfile(os.path.join(case, "prediction.csv")):
                out.write(f"| {m} | {label} | not run yet | | | | |\n")
                continue
            pred = read_rows(os.path.join(case, "prediction.csv"))
            cal = read_rows(os.path.join(case, "calibrated.csv"))
            run = read_rows(os.path.join(case, "run.csv"))[0]
            errors = []
            for r in pred:
                held = r.get("held_out") == "1"
                e = f"{r['sigma3_kPa']}: {float(r['error_pct']):+.1f}%"
                errors.append(f"**{e}**" if held else e)
                if c == "all":
                    fitted_errors.append(abs(float(r["error_pct"])))
                elif held:
                    held_errors.append(abs(float(r["error_pct"])))
            values = "; ".join(f"{x['parameter']} {fmt(x['value'])} [{fmt(x['low95'])}, {fmt(x['high95'])}]" for x in cal)
            secs = int(run["seconds"])
            out.write(f"| {m} | {label} | {', '.join(errors)} | {values} | {cal[0]['runs']} | "
                      f"{secs // 3600}h{secs % 3600 // 60:02d}m | {run['commit']} |\n")
    if len(fitted_errors) == 9:
        out.write(f"\nThe nine tests with all pressures fitted: mean |error| **{statistics.fmean(fitted_errors):.1f}%**, at "
                  f"most {max(fitted_errors):.1f}%.\n")
    if len(held_errors) == 9:
        out.write(f"\nThe nine held-out pressures, each predicted from a fit on the other two: mean |error| "
                  f"**{statistics.fmean(held_errors):.1f}%**, at most {max(held_errors):.1f}%.\n")
    return out.getvalue(), [folder], "perf/table6_loop.sh (each case's files copied as data/results/table6_loop/README.md says)"


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
    rows = [r for level in ("lab", "precise") for r in read_rows(os.path.join(folder, level + ".csv"))]
    cost = (f"\n\nThe two levels: {len(rows)} cases, {sum(float(r['seconds']) for r in rows) / 3600:.1f} hours of runs in "
            "all (each case's seconds).")
    return text.strip() + cost + "\n", [folder], "perf/identification_table.sh (tools/sweep_table.py for the table)"


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
                                      'METHOD=rescatter_max at 9827c3e; METHOD=specimens at 82f074b, cases 17-30 of 1x at ac9b891 and fb5505c, the same code as b79c38d; '
                                      'METHOD=one_specimen SEARCH=one_specimen at 933e339 where no range was widened, the rest at 9286505; '
                                      'METHOD=one_specimen_unclamped REUSE=one_specimen SIZES=1 at 777110e), '
                                      'tools/coverage_table.py data/sweeps/coverage')


def frictionless_plan(root):
    """A frictionless base's runs against the plan (issue 87): the consolidation after a preparation, by the runs'
    sliding friction, over the plan's packing estimate; below mu_s 0.0075 the plan counts 0.5 to 20 such packings
    (host/lab/run_cost.hpp, ResettleCost), above it a share of the shear."""
    path = os.path.join(root, "data/sweeps/plan/frictionless_consolidation.csv")
    rows = read_rows(path)
    out = io.StringIO()
    out.write("| cell | balls | seed | sigma3 kPa | preparation mu_s | mu_s | consolidation steps | over the packing "
              "estimate | within the plan |\n|---|---|---|---|---|---|---|---|---|\n")
    for r in rows:
        ratio = float(r["consolidation_steps"]) / float(r["packing_steps_est"])
        counted = "0.5-20 packings" if float(r["mu_s"]) < 0.0075 else "a share of the shear"
        inside = (0.5 <= ratio <= 20) if float(r["mu_s"]) < 0.0075 else ratio < 0.5
        out.write(f"| {r['cell']} | {r['balls']} | {r['seed']} | {r['sigma3_kPa']} | {r['prep_mu_s']} | {r['mu_s']} | "
                  f"{r['consolidation_steps']} | {ratio:.3g} | {'yes' if inside else 'NO'} ({counted}) |\n")
    return out.getvalue(), [path], ("triaxdem periodic CONFIG on each cell's config with mu_s, sigma3_kPa and [run] "
                                    "seed set, read from its 'consolidated in N steps' line")


def k0_jaky(root):
    """An oedometer's K0 on loading (1,600 kPa, after seating at 100 kPa) against Jaky's 1 - sin(phi), phi the peak
    friction angle of the same cell's periodic triaxial test at 400 kPa: 120-ball cells, mu_s 0.3, three seeds at each
    contact stiffness."""
    folder = os.path.join(root, "data/sweeps/compression")
    rows = read_rows(os.path.join(folder, "k0_jaky.csv"))
    out = io.StringIO()
    out.write("| emod Pa | K0 (each seed) | peak phi deg | K0 - Jaky with the peak angle | mean | K0 - Jaky with the end-of-test "
              "angle | mean |\n|---|---|---|---|---|---|---|\n")
    for emod in dict.fromkeys(r["emod_Pa"] for r in rows):
        sel = [r for r in rows if r["emod_Pa"] == emod]
        d_peak = [float(r["K0_at_1600kPa"]) - float(r["jaky_peak"]) for r in sel]
        d_end = [float(r["K0_at_1600kPa"]) - float(r["jaky_end"]) for r in sel]
        out.write(f"| {emod} | {', '.join(fmt(r['K0_at_1600kPa']) for r in sel)} | "
                  f"{', '.join(fmt(r['phi_peak_deg_400kPa']) for r in sel)} | {', '.join(f'{v:+.3f}' for v in d_peak)} | "
                  f"**{statistics.fmean(d_peak):+.3f}** | {', '.join(f'{v:+.3f}' for v in d_end)} | "
                  f"{statistics.fmean(d_end):+.3f} |\n")
    return out.getvalue(), [folder], "BUILD=build SRC=. bash data/sweeps/compression/run.sh (from a scratch folder)"


def psd_width(root):
    """What a wider size distribution does to the calibration cell (S-1's friction, 600 balls) at 100 kPa: lognormal
    sizes by mass about D50 2 mm, every cell inserted at the same solid fraction, three seeds each."""
    folder = os.path.join(root, "data/sweeps/psd")
    rows = read_rows(os.path.join(folder, "psd_width.csv"))
    out = io.StringIO()
    out.write("| log_sd | sizes drawn mm | void ratio after consolidation (mean, seeds) | q_peak kPa (mean, seeds) | "
              "peak phi deg (mean) |\n|---|---|---|---|---|\n")
    for s in dict.fromkeys(r["log_sd"] for r in rows):
        sel = [r for r in rows if r["log_sd"] == s]
        e = [float(r["void_ratio0"]) for r in sel]
        q = [float(r["q_peak_kPa"]) for r in sel]
        phi = [float(r["phi_peak_deg"]) for r in sel]
        lo = min(float(r["smallest_mm"]) for r in sel)
        hi = max(float(r["largest_mm"]) for r in sel)
        out.write(f"| {s} | {lo:.3g}-{hi:.3g} | **{statistics.fmean(e):.4f}** ({', '.join(f'{v:.4f}' for v in e)}) | "
                  f"**{statistics.fmean(q):.1f}** ({', '.join(f'{v:.1f}' for v in q)}) | {statistics.fmean(phi):.2f} |\n")
    return out.getvalue(), [folder], "BUILD=build SRC=. bash data/sweeps/psd/run.sh (from a scratch folder)"


def polydisperse(root):
    """A polydisperse calibration: a cell of lognormal sizes by mass (D50 2 mm, log_sd 0.1, 300 balls) calibrated on
    synthetic curves of its own model at 100, 200 and 300 kPa, made on specimens the calibration never runs; the
    generating values are the config's (mu_s 0.15, mu_r 0.015)."""
    folder = os.path.join(root, "data/runs/polydisperse")
    truth = {"mu_s": 0.15, "mu_r": 0.015}
    out = io.StringIO()
    out.write("| parameter | generating | calibrated | 95% interval | holds it |\n|---|---|---|---|---|\n")
    rows = read_rows(os.path.join(folder, "calibrated.csv"))
    for r in rows:
        t = truth[r["parameter"]]
        inside = float(r["low95"]) <= t <= float(r["high95"])
        out.write(f"| {r['parameter']} | {t} | {fmt(r['value'])} | [{fmt(r['low95'])}, {fmt(r['high95'])}] | "
                  f"{'yes' if inside else 'NO'} |\n")
    out.write(f"\nchi2 {fmt(rows[0]['chi2'])} on {rows[0]['data']} data, {rows[0]['runs']} runs.\n")
    return out.getvalue(), [folder], ("triaxdem calibrate data/runs/polydisperse/data.csv --config "
                                      "data/runs/polydisperse/base.toml --predict none -j 2 (data: data/runs/README.md)")


def joint_compression(root):
    """Compression tests calibrated with triaxial peaks: data made at emod 2e8 Pa, mu_s 0.25 (the hidden-effect cell,
    whose base is 1e8 and 0.15) on specimens no calibration runs: the peak deviator of three drained tests (100-300
    kPa), an oedometer and an isotropic compression from 100 to 800 kPa; emod and mu_s calibrated from the base on the
    peaks alone, with the oedometer (`--compression`), with both compression tests, and with the oedometer on peaks that
    give their void ratio after consolidation (which the cells are then prepared to, at the base's stiffness)."""
    folder = os.path.join(root, "data/sweeps/joint")
    rows = read_rows(os.path.join(folder, "joint.csv"))
    names = {"peaks_alone": "peaks alone", "peaks_oedometer": "peaks and the oedometer",
             "peaks_both": "peaks, the oedometer and the isotropic test",
             "peaks_state_oedometer": "peaks with their void ratio, and the oedometer"}
    out = io.StringIO()
    out.write("| data | emod Pa (95% interval) | holds 2e8 | mu_s (95% interval) | holds 0.25 | chi2 / data | runs | "
              "time |\n|---|---|---|---|---|---|---|---|\n")
    for case in dict.fromkeys(r["case"] for r in rows):
        by = {r["parameter"]: r for r in rows if r["case"] == case}
        cells = []
        for p in ("emod_Pa", "mu_s"):
            r = by[p]
            inside = float(r["low95"]) <= float(r["truth"]) <= float(r["high95"])
            cells.append(f"{fmt(r['value'])} [{fmt(r['low95'])}, {fmt(r['high95'])}] | {'yes' if inside else 'NO'}")
        r = by["emod_Pa"]
        secs = int(r["seconds"])
        out.write(f"| {names.get(case, case)} | {' | '.join(cells)} | {fmt(r['chi2'])} / {r['data']} | {r['runs']} | "
                  f"{secs // 60}m{secs % 60:02d}s |\n")
    return out.getvalue(), [folder], "BUILD=build SRC=. bash data/sweeps/joint/run.sh > joint.csv (from a scratch folder)"


def preparation_stiffness(root):
    """Whether the stiffness a specimen is prepared with moves its triaxial test: the hidden-effect cell (120 balls,
    preparation friction 0.03) at emod 2e8 Pa, mu_s 0.25, 32 packing seeds prepared at emod 2e8 and at 1e8 and each
    tested at 2e8 (perf/inertial_scan --preparation-emod), as a calibration with emod free tests cells prepared once
    at the base's emod against data the material prepared at its own. The peak's shift from preparing at 1e8, with its
    standard error over the specimens, and in mu_s through the same specimens' peak at mu_s 0.30; then the features the
    preparation does move (beyond half a specimen's scatter)."""
    folder = os.path.join(root, "data/sweeps/preparation")
    out = io.StringIO()
    out.write("| sigma3 kPa | q_peak / sigma3 (prepared at 2e8) | shift, prepared at 1e8 | in mu_s |\n|---|---|---|---|\n")
    for r in read_rows(os.path.join(folder, "summary.csv")):
        out.write(f"| {r['sigma3_kPa']} | {fmt(r['qpeak_over_sigma3_prep2e8'])} | {float(r['shift_prep1e8']):+.3f} "
                  f"+- {fmt(r['shift_se'], 2)} | {float(r['mu_s_equivalent']):+.3f} +- {fmt(r['mu_s_se'], 2)} |\n")
    moved = [r for r in read_rows(os.path.join(folder, "preparation.csv"))
             if float(r["preparation_emod_Pa"]) != 2e8 and float(r["shift_over_scatter"]) >= 0.5]
    out.write("\n| sigma3 kPa | feature | strain % | shift / one specimen's scatter |\n|---|---|---|---|\n")
    for r in moved:
        feature = "q_peak" if float(r["strain_pct"]) == 0 else r["feature"]
        out.write(f"| {r['sigma3_kPa']} | {feature} | {r['strain_pct']} | {float(r['mean_shift']) / float(r['reference_sd']):+.2f}"
                  f" +- {fmt(r['shift_se_over_scatter'], 2)} |\n")
    return out.getvalue(), [folder], "BUILD=build SRC=. SPECIMENS=32 bash data/sweeps/preparation/run.sh (from a scratch folder)"


def plan_particle_steps(path):
    """A `calibrate --plan` output's total particle-steps ("calibrate: in all 8.7e+09 particle-steps, ...")."""
    for line in open(path):
        if line.startswith("calibrate: in all "):
            return float(line.split()[3])
    raise SystemExit(f"results_page: {path} holds no 'calibrate: in all' line")


def job_runs(path):
    """A calibration log's runs ("calibrate: 132 runs in 3m22s; ...") and the plan beside the time taken."""
    runs, plan = None, ""
    for line in open(path):
        if line.startswith("calibrate: ") and " runs in " in line and runs is None:
            runs = int(line.split()[1])
        if line.startswith("calibrate: the plan said"):
            plan = line.split("calibrate: ", 1)[1].strip()
    if runs is None:
        raise SystemExit(f"results_page: {path} holds no 'calibrate: N runs in' line")
    return runs, plan


# The coverage rows of the current code's one specimen a point (perf/coverage.sh METHOD): the bootstrap's minima
# unclamped (777110e), the same cases' data and runs as `one_specimen` (REUSE).
CURRENT_COVERAGE = "one_specimen_unclamped"


def job_took(path):
    """A job's seconds and its words from "...: the plan said about X; the job took 3m49s"."""
    for line in open(path):
        if "the plan said" in line and "the job took" in line:
            took = line.rsplit("the job took ", 1)[1].strip()
            m, sec = took.rstrip("s").split("m")
            return 60 * int(m) + int(sec), line.split(": ", 1)[1].strip()
    raise SystemExit(f"results_page: {path} holds no 'the job took' line")


def calibration_goals(root):
    """Issue 85's goals for one specimen a point (`[calibrate] method = "one_specimen"`) beside the ensemble: the
    runs a calibration takes, the particle-steps its plan counts, and how often its 95% intervals hold the truth.
    Runs in all are the calibration's (scatter runs at the base and at the answer, the search), not the cell's bias
    check on larger cells. The coverage counts are of the 30 cases of the cell's size (perf/coverage.sh, the current
    code's rows). A goal with no
    file behind it is marked not measured."""
    plans = os.path.join(root, "data/sweeps/plan/walled_4000")
    s1 = os.path.join(root, "data/runs/S1_one_specimen")
    cov = os.path.join(root, "data/sweeps/coverage")
    out = io.StringIO()
    out.write("| goal | measured | goal's bound | met |\n|---|---|---|---|\n")
    for folder, words in ((s1, "one specimen a point"), (s1 + "_s4", "the same with 4 scatter specimens")):
        runs, plan = job_runs(os.path.join(folder, "calibrate.log"))
        out.write(f"| Table 6 S-1, simulator runs in all, {words} | {runs} ({plan}) | <= 60 | "
                  f"{'yes' if runs <= 60 else 'no'} |\n")
    one = {r["parameter"]: r for r in read_rows(os.path.join(s1, "calibrated.csv"))}
    ens = {r["parameter"]: r for r in read_rows(os.path.join(root, "data/runs/S1_table6_periodic/calibrated.csv"))}
    inside = lambda r, v: float(r["low95"]) <= float(v) <= float(r["high95"])
    for p in one:
        both = inside(ens[p], one[p]["value"]) and inside(one[p], ens[p]["value"])
        out.write(f"| Table 6 S-1, {p}: each method's optimum inside the other's 95% interval (one specimen "
                  f"{fmt(one[p]['value'])} [{fmt(one[p]['low95'])}, {fmt(one[p]['high95'])}], the ensemble "
                  f"{fmt(ens[p]['value'])} [{fmt(ens[p]['low95'])}, {fmt(ens[p]['high95'])}]) | "
                  f"{'both' if both else 'not both'} | both | {'yes' if both else 'no'} |\n")
    steps = {c: plan_particle_steps(os.path.join(plans, c + ".plan.txt"))
             for c in ("defaults", "ensemble2", "one_specimen", "one_specimen_s4")}
    words = {"defaults": "the defaults (ensemble auto)", "ensemble2": "ensemble 2",
             "one_specimen": "one specimen a point", "one_specimen_s4": "one specimen a point, 4 scatter specimens"}
    for c, v in steps.items():
        out.write(f"| walled cell of 4,000 balls, particle-steps its plan counts: {words[c]} | {v:.2g} | <= 8e9 | "
                  f"{'yes' if v <= 8e9 else 'no'} |\n")
    rows = [r for r in read_rows(os.path.join(cov, CURRENT_COVERAGE + ".csv")) if r["size"] == "1"]
    held = lambda p: sum(coverage_table.num(r, p + "_lo") <= coverage_table.num(r, p + "_true") <=
                         coverage_table.num(r, p + "_hi") for r in rows)
    joint = sum(coverage_table.num(r, "region_rise") <= 1 for r in rows)
    for name, k in (("joint region", joint), ("mu_s interval", held("mu_s")), ("mu_r interval", held("mu_r"))):
        out.write(f"| coverage, {name}, {len(rows)} cases of the cell's size | {k} of {len(rows)} | 27-30 of 30 | "
                  f"{'yes' if k >= 27 and len(rows) >= 30 else 'no'} |\n")
    base = [r for r in read_rows(os.path.join(cov, "ensemble.csv")) if r["size"] == "1"]
    ratio = coverage_table.against(rows, base)
    worst = max(float(x) for x in ratio.split(" (")[0].split(" / "))
    out.write(f"| median interval width over the first ensemble method's, the same cases (mu_s / mu_r) | {ratio} | "
              f"<= 1.3 | {'yes' if worst <= 1.3 else 'no'} |\n")
    walled = os.path.join(root, "data/runs/walled_one_specimen")
    runs, plan = job_runs(os.path.join(walled, "calibrate.log"))
    mu_s = {r["parameter"]: r for r in read_rows(os.path.join(walled, "calibrated.csv"))}["mu_s"]
    out.write(f"| YADE's walled 1,000-ball file (generating mu_s 0.4), simulator runs in all, one specimen a point | "
              f"{runs}, mu_s {fmt(mu_s['value'])} [{fmt(mu_s['low95'])}, {fmt(mu_s['high95'])}] ({plan}) | <= 60 | "
              f"{'yes' if runs <= 60 else 'no'} |\n")
    took = job_took(os.path.join(root, "data/runs/diagnose_linear/diagnose.log"))
    out.write(f"| the default diagnosis of YADE's linear file (it searches with the ensemble) | {took[1]} | <= 2 minutes "
              f"| {'yes' if took[0] <= 120 else 'no'} |\n")
    return out.getvalue(), [s1, s1 + "_s4", os.path.join(root, "data/runs/S1_table6_periodic"), plans, cov, walled,
                            os.path.join(root, "data/runs/diagnose_linear")], ("the S-1, walled and diagnosis commands in data/runs/README.md; triaxdem calibrate "
                                              "tests/data/crosscode/walled_seed1.csv --config "
                                              "data/sweeps/plan/walled_4000/<case>.toml --plan; perf/coverage.sh")


def inertial_scan(root):
    """How fast a calibration cell may shear: the same 8 specimens of configs/calibration/base.toml (200 balls, to 10%)
    sheared at 100 and 300 kPa at each inertial number, each curve feature's mean shift from the slowest rate over the
    specimens' own scatter (SD); the largest over the features, strains and pressures."""
    path = os.path.join(root, "data/sweeps/inertial_scan_base_8specimens.csv")
    rows = read_rows(path)
    out = io.StringIO()
    out.write("| inertial number | largest shift (specimen SDs) | where |\n|---|---|---|\n")
    for inertial in dict.fromkeys(r["inertial"] for r in rows):
        worst = max((r for r in rows if r["inertial"] == inertial), key=lambda r: abs(float(r["shift_over_scatter"])))
        shift = abs(float(worst["shift_over_scatter"]))
        where = f"{worst['feature']} at {worst['strain_pct']}%, {worst['sigma3_kPa']} kPa" if shift > 0 else "the reference"
        out.write(f"| {inertial} | {shift:.2f} | {where} |\n")
    return out.getvalue(), [path], "perf/inertial_scan --specimens 8 --pressures 100,300 -j 2 -o runs/inertial_scan.csv"


def device_blocks(path):
    """A device log's blocks: each "== title" line and the lines under it, in order."""
    blocks, title = [], ""
    for line in open(path):
        if line.startswith("== "):
            title = line[3:].strip()
            blocks.append((title, []))
        elif blocks:
            blocks[-1][1].append(line.rstrip("\n"))
    return blocks


def device_run(root):
    """The latest device run, on an H200 (perf/device_check.sh with three full-scale runs of the paper's S-1 test
    after it; the log keeps what each part printed), and one figure from the third run, on an H100: calibration cells
    as processes sharing one device. The shear's host work is `host_control_ns` of the shear's row in timings.csv,
    over the particle-step's time at its rate."""
    fifth = os.path.join(root, "docs/device_runs/2026-11-30_h200_fifth.log")
    third = os.path.join(root, "docs/device_runs/2026-11-27_h100_third.log")
    blocks = device_blocks(fifth)
    part = lambda start: next(body for title, body in blocks if title.startswith(start))
    first = lambda body, word: next(l for l in body if l.split()[:1] == [word])
    field = lambda text, key: float(text.split(key, 1)[1].split()[0].rstrip("M/s"))
    tests = next(l for l in part("the suite's kernels tests") if l.startswith("passed "))
    packing = first(part("particle-steps/s at 1000000 balls"), "1000000")
    launch = first(part("launch overhead (64 balls"), "64")
    bench = {l.split("/")[1] if l.startswith("BM_CellBatch") else "alone": field(l, "particle_steps/s=")
             for l in part("calibration cells as one batch")
             if l.startswith(("BM_CellBatch/64/", "BM_CellBatch/512/", "BM_TimeLoop/9/1/"))}
    compared = [l for l in part("periodic cell against the CPU's") + part("membrane triaxial test against the CPU's")
                if l.startswith("| ") and l.split("|")[2].strip().isdigit()]
    same = sum(l.split("|")[4].strip() == "identical" for l in compared)
    columns = next(l for _, body in blocks for l in body if l.startswith("stage,balls,")).split(",")  # timings.csv's
    walls, peaks, host = [], set(), []
    for title, body in blocks:
        if "20 records" in title or "overlap off" in title:
            continue  # the other settings, not the default run's
        for l in body:
            if l.startswith("result: q_peak"):
                peaks.add(l.split()[2])
                minutes, seconds = l.rsplit("wall time ", 1)[1].rstrip("s").split("m")
                walls.append(60 * int(minutes) + int(seconds))
            if l.startswith("shear,53704,"):
                row = dict(zip(columns, l.split(",")))
                ns = float(row["host_control_ns"])
                host.append((ns, ns * float(row["particle_steps_per_s"]) / 1e9))  # and over a particle-step's ns
    alone, *shared = [field(l, "; ") for l in open(third) if l.startswith("time loop (test)")][-5:]
    out = io.StringIO()
    out.write("| case | measured |\n|---|---|\n")
    out.write(f"| the suite's kernel and reference tests | {tests} |\n")
    out.write(f"| the benchmark packing, 10^6 balls | {float(packing.split()[1]):.3g} particle-steps/s |\n")
    out.write(f"| 64 balls, a step (the launches' overhead) | {64 * float(launch.split()[2]) / 1000:.0f} us |\n")
    out.write(f"| calibration cells of 729 balls: one alone, a batch of 64, of 512 (particle-steps/s) | "
              f"{bench['alone'] * 1e6:.3g}; {bench['64'] * 1e6:.3g} ({bench['64'] / bench['alone']:.0f}x); "
              f"{bench['512'] * 1e6:.3g} ({bench['512'] / bench['alone']:.0f}x) |\n")
    out.write(f"| the periodic cell's and the membrane test's files against the CPU build's | {same} of {len(compared)} "
              "identical |\n")
    out.write(f"| S-1 at full scale (53,704 beads), consolidation and shear to 15%, the specimen made | "
              f"{min(walls)}-{max(walls)} s in {len(walls)} runs, q_peak {', '.join(sorted(peaks))} kPa |\n")
    ns, share = zip(*host)
    out.write(f"| the shear's host work a particle-step in those runs | {min(ns):.2f}-{max(ns):.2f} ns, "
              f"{min(share):.1%} to {max(share):.1%} of the particle-step |\n")
    out.write(f"| H100: 4 cells as 4 processes at once against one alone (particle-steps/s) | {alone:.3g} alone; "
              f"{sum(shared):.3g} for the four together: **{alone / sum(shared):.1f} times slower** |\n")
    return out.getvalue(), [fifth, third], "perf/device_check.sh and the full-scale runs (each log's command at its top)"


def runs_of(rows, keys):
    """Rows grouped by the values of `keys` (one benchmark run each), in file order."""
    groups = {}
    for r in rows:
        groups.setdefault(tuple(r[k] for k in keys), []).append(r)
    return groups


def peer_benchmark(root):
    """Throughput side by side with LIGGGHTS and LAMMPS (Debian's packages) on one packing of 54,872 balls, each code
    on all cores, run one after the other by one script; particle-steps per second, the median of the runs. The runs
    inside one benchmark spread by several %, so ratios are what compare, not one machine's rates with another's."""
    path = os.path.join(root, "data/results/peer_benchmark/rates.csv")
    out = io.StringIO()
    out.write("| date | commit | machine | cores | triaxdem | LIGGGHTS | LAMMPS | triaxdem / faster peer |\n"
              "|---|---|---|---|---|---|---|---|\n")
    for (date, commit, machine, cores), g in runs_of(read_rows(path), ("date", "commit", "machine", "cores")).items():
        rate = {r["code"]: float(r["median_psteps_per_s"]) for r in g}
        peers = [v for k, v in rate.items() if k != "triaxdem"]
        ratio = f"**{rate['triaxdem'] / max(peers):.2f}**" if peers else "-"
        cell = lambda k: f"{rate[k] / 1e6:.3g} M" if k in rate else "-"
        out.write(f"| {date} | {commit} | {machine} | {cores} | {cell('triaxdem')} | {cell('liggghts')} | "
                  f"{cell('lammps')} | {ratio} |\n")
    return out.getvalue(), [path], "STEPS=1000 REPS=5 CSV=data/results/peer_benchmark/rates.csv perf/peer_benchmark.sh"


def scaling(root):
    """The cost per particle-step against the ball count: the benchmark packing at k^3 balls, 300 steps on all cores;
    stage seconds from the run's own timers, the peak resident memory over the balls (the program itself at small N).
    The rise is the largest size's cost over the cheapest size's."""
    path = os.path.join(root, "data/results/scaling/scaling.csv")
    out = io.StringIO()
    for (date, commit, machine, threads), g in runs_of(read_rows(path), ("date", "commit", "machine", "threads")).items():
        out.write(f"{date}, {commit}, {machine}, {threads} threads:\n\n| balls | particle-steps/s | ns per particle-step | "
                  "rebuild s | forces s | gather + integrate s | bytes/ball (peak RSS) |\n|---|---|---|---|---|---|---|\n")
        for r in g:
            out.write(f"| {int(r['balls']):,} | {float(r['psteps_per_s']) / 1e6:.3g} M | {float(r['ns_per_pstep']):.1f} | "
                      f"{r['rebuild_s']} | {r['forces_s']} | {r['integrate_s']} | {float(r['bytes_per_ball']):,.0f} |\n")
        cost = [float(r["ns_per_pstep"]) for r in g]
        out.write(f"\nFrom the cheapest size to {int(g[-1]['balls']):,} balls the cost per particle-step rises by "
                  f"**{100 * (cost[-1] / min(cost) - 1):.0f}%**.\n\n")
    return out.getvalue().rstrip("\n") + "\n", [path], "STEPS=300 CSV=data/results/scaling/scaling.csv perf/scaling.sh"


SECTIONS = [
    ("Table 6, S-1, calibrated on the periodic cell and predicted by the membrane test", table6_periodic),
    ("Table 6 by the loop: fitted, and each pressure held out", table6_loop),
    ("Another code's walled data, calibrated on the periodic cell and predicted between walls", walled_on_periodic),
    ("The diagnosis: hidden effects named, and false alarms", identification),
    ("Coverage of the 95% intervals", coverage),
    ("One specimen a point against its goals", calibration_goals),
    ("A frictionless base's consolidation against the plan", frictionless_plan),
    ("Side by side with LIGGGHTS and LAMMPS", peer_benchmark),
    ("Cost per particle-step against the ball count", scaling),
    ("The latest device run (H200)", device_run),
    ("How fast a calibration cell may shear", inertial_scan),
    ("An oedometer's K0 against Jaky's", k0_jaky),
    ("Compression tests with the triaxial ones", joint_compression),
    ("The preparation's stiffness against the test", preparation_stiffness),
    ("What a wider size distribution does", psd_width),
    ("A polydisperse calibration", polydisperse),
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
        about = " ".join((make.__doc__ or "").split())  # a docstring's lines as one paragraph
        out.write(f"\n## {title}\n\n{about} From {where}; made by `{command}`.\n\n{text}")
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
