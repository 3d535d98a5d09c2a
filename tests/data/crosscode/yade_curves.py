# -*- coding: utf-8 -*-
"""What the YADE cross-code scripts share: the strains at which a test's rows are taken, their interpolation between
time steps, YADE's package version and the CSV file. Imported by yade_peri_triax.py and yade_walled_triax.py from
their own folder."""
import subprocess

# Rows every 0.02% axial strain to 1%, every 0.1% to 15%.
TARGETS_PCT = [0.02 * k for k in range(0, 51)] + [1.0 + 0.1 * k for k in range(1, 141)]


def take_rows(st, cur, rows):
    """cur = (eps_a, q, eps_v, lateral stress) of this step (SI, fractions); appends to `rows` each target strain
    passed since the last call, linearly interpolated between the two steps, as (sigma3 kPa, eps_a %, q kPa,
    eps_v %, e0), and keeps the largest |lateral - sigma3| / sigma3 of the rows in st['laterr']. st holds the test's
    sigma3 (kPa), e0, the next target's index k and the previous step. Returns True when every target is taken."""
    eps = cur[0]
    prev = st.get('prev')
    while st['k'] < len(TARGETS_PCT) and eps * 100 >= TARGETS_PCT[st['k']] - 1e-12:
        t = TARGETS_PCT[st['k']] / 100
        w = 1.0 if prev is None or eps <= prev[0] else min(1.0, max(0.0, (t - prev[0]) / (eps - prev[0])))
        vals = [cur[j] if prev is None else prev[j] + w * (cur[j] - prev[j]) for j in range(4)]
        rows.append((st['sigma3'], TARGETS_PCT[st['k']], vals[1] / 1e3, vals[2] * 100, st['e0']))
        st['laterr'] = max(st.get('laterr', 0.0), abs(vals[3] / 1e3 - st['sigma3']) / st['sigma3'])
        st['k'] += 1
    st['prev'] = cur
    return st['k'] >= len(TARGETS_PCT)


def debian_version():
    """The installed Debian package's version of yade, '?' where dpkg cannot tell."""
    try:
        return subprocess.run(['dpkg-query', '-W', '-f=${Version}', 'yade'], capture_output=True, text=True).stdout
    except Exception:
        return '?'


def write_csv(path, header, rows, material, q_measure=None, balls=None):
    """The header lines (each starting with '#'), the column line and the rows; q_measure, where given, on every row
    (which deviator q is: fixed_area or area_corrected), and balls as specimen_balls (between walls the specimen's
    size is part of the test)."""
    extra = (',' + q_measure if q_measure else '') + (',%d' % balls if balls else '')
    with open(path, 'w') as f:
        f.write('\n'.join(header) + '\n')
        f.write('material,sigma3_kPa,eps_a_pct,q_kPa,eps_v_pct,void_ratio' + (',q_measure' if q_measure else '') +
                (',specimen_balls' if balls else '') + '\n')
        for r in rows:
            f.write('%s,%.6g,%.6g,%.6g,%.6g,%.6g%s\n' % (material, r[0], r[1], r[2], r[3], r[4], extra))
