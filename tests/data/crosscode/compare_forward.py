"""The walled cell's runs at the generating friction (forward_walled.sh) against YADE's walled data: for each pressure
and compared quantity (q at 1, 3 and 8% and its peak, eps_v at 3 and 8%), the runs' value at the data's void ratio (a
line fitted over the runs' void ratios), the data's value, and their difference in the runs' scatter about that line
(one specimen's scatter, which a single data specimen also has).
    compare_forward.py DATA.csv RUNS_FOLDER
"""
import csv
import glob
import sys

import numpy as np


def quantities(e, q, v):
    e, q, v = map(np.asarray, (e, q, v))
    return {'q 1%': np.interp(1, e, q), 'q 3%': np.interp(3, e, q), 'q 8%': np.interp(8, e, q), 'q peak': q.max(),
            'eps_v 3%': np.interp(3, e, v), 'eps_v 8%': np.interp(8, e, v)}


data = {}
for r in csv.DictReader(l for l in open(sys.argv[1]) if not l.startswith('#')):
    data.setdefault(float(r['sigma3_kPa']), []).append(
        (float(r['eps_a_pct']), float(r['q_kPa']), float(r['eps_v_pct']), float(r['void_ratio'])))
for p in sorted(data):
    y = np.array(data[p])
    measured, e_data = quantities(y[:, 0], y[:, 1], y[:, 2]), y[0, 3]
    runs = []
    for d in sorted(glob.glob('%s/out_w_%d_*/series.csv' % (sys.argv[2], p))):
        s = list(csv.DictReader(open(d)))
        if not s or float(s[-1]['eps_a_pct']) < 14:
            continue  # a run that stopped early (a blow-up) is left out and counted below
        runs.append((float(s[0]['void_ratio']), quantities(*[[float(r[k]) for r in s] for k in
                                                             ('eps_a_pct', 'q_kPa', 'eps_v_pct')])))
    if len(runs) < 3:
        print('sigma3 %g kPa: %d runs reached 14%%, too few to compare' % (p, len(runs)))
        continue
    e0 = np.array([r[0] for r in runs])
    print('sigma3 %g kPa: data e0 %.4f; %d runs, e0 %.4f to %.4f' % (p, e_data, len(runs), e0.min(), e0.max()))
    A = np.vstack([np.ones_like(e0), e0 - e_data]).T
    for k, m in measured.items():
        x = np.array([r[1][k] for r in runs])
        c = np.linalg.lstsq(A, x, rcond=None)[0]
        sd = np.sqrt(np.sum((A @ c - x) ** 2) / max(1, len(x) - 2))
        print('  %-8s data %8.3f  runs at the data e0 %8.3f (scatter sd %6.3f)  difference %+6.1f%% = %+.1f sd' %
              (k, m, c[0], sd, 100 * (c[0] - m) / abs(m), (c[0] - m) / sd if sd > 0 else 0))
