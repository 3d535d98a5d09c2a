# -*- coding: utf-8 -*-
"""Periodic-cell drained triaxial tests with YADE (cross-code test data for triaxdem).

Run:  yade -j1 -n -x yade_peri_triax.py law=linear seed=1 n=1500 pressures=60,150,300 mat=lin out=linear_seed1.csv
Optional key=value arguments (defaults below): inertial=1e-3 damping=0.5 prep_mu=0.1|0.05 prep_mur=0 version=...
  law        linear | hertz
  seed       makeCloud seed (the same cloud for every pressure)
  n          number of balls
  pressures  confining pressures in kPa, comma separated
  mat        material name written in the `material` column
  out        CSV file written

Each pressure uses its own, freshly prepared specimen from the same seed: random loose cloud, isotropic
compaction to sigma3 with the preparation friction (prep_mu, rolling resistance prep_mur = 0 by default),
sliding friction and rolling cap raised to the test values on every contact, re-equilibration,
then drained shear (z compressed at a constant velocity gradient, x and y held at sigma3) to 15 % axial
strain. Stresses are controlled by a PI servo on O.cell.velGrad driven by the contact stress (utils.getStress):
YADE's PeriTriaxController was tried first, but with 2023.02a its own stress estimate disagreed with
utils.getStress by up to a factor 2 on one axis and it chattered at +-maxStrainRate, so it is not used.

YADE's parameters (found by reading the 2023.02a class documentation and YADE's
CohesiveFrictionalContactLaw.cpp (an older copy, bchareyre/yade-mpi), and checked numerically on a two-ball contact with
this installation):
  Ip2_FrictMat_FrictMat_FrictPhys (used by Ip2_CohFrictMat_CohFrictMat_CohFrictPhys):
      kn = E1 D1 E2 D2 / (E1 D1 + E2 D2)  -> equal spheres: kn = E r;   ks = poisson * kn
  Ip2_CohFrictMat_CohFrictMat_CohFrictPhys: kr = alphaKr * ks * R1 R2, ktw = alphaKtw * ks * R1 R2,
      maxRollPl = min(etaRoll R1, etaRoll R2); Law2_ScGeom6D_CohFrictPhys_CohesionMoment caps
      |M_bend| <= maxRollPl |Fn| (no cap at all when maxRollPl = 0).
  Ip2_FrictMat_FrictMat_MindlinPhys: E* = E1 E2 / ((1-v1^2) E2 + (1-v2^2) E1) (= E/(2(1-v^2))),
      R = r1 r2/(r1+r2), Fn = kno un^1.5 with kno = 4/3 E* sqrt(R), ks = kso sqrt(un), kso = 2 sqrt(4R) G/(2-v),
      kr = krot (constant), maxBendPl = eta * (r1+r2)/2, Law2_ScGeom_MindlinPhys_Mindlin(includeMoment)
      caps |M_bend| <= maxBendPl |Fn|.
triaxdem (kernels/contact/contact_law.hpp): kn = pi r^2 E / (r1+r2), ks = kn/1.5, kr = ks Rbar^2, Rbar = r1 r2/(r1+r2),
|M| <= mu_r Rbar Fn.  Hence for equal spheres (r = 1 mm, Rbar = r/2):
  linear: young = pi E / 2 (E = 1e8), poisson = 1/1.5, alphaKr = 1/4 (kr identical), etaRoll = mu_r / 2.
  hertz:  mu_r(triaxdem) = eta * r / Rbar = 2 eta; ks/kt = 2(1-v)/(2-v) equals triaxdem's 1/1.5 for v = 0.5.
"""
import sys, math, time, os

# ---------------------------------------------------------------- arguments
args = dict(a.split('=', 1) for a in sys.argv[1:] if '=' in a)
LAW = args.get('law', os.environ.get('LAW', 'linear'))
SEED = int(args.get('seed', os.environ.get('SEED', '1')))
NBALLS = int(args.get('n', os.environ.get('NBALLS', '1500')))
PRESSURES = [float(p) for p in args.get('pressures', os.environ.get('PRESSURES', '60,150,300')).split(',')]
MATNAME = args.get('mat', 'lin' if LAW == 'linear' else 'hz')
OUT = args.get('out', os.environ.get('OUT', '%s_seed%d.csv' % (LAW, SEED)))
INERTIAL = float(args.get('inertial', '1e-3'))
DAMPING = float(args.get('damping', '0.5'))
PREP_MU = float(args.get('prep_mu', '0.1' if LAW == 'linear' else '0.05'))
PREP_MUR = float(args.get('prep_mur', '0'))  # rolling friction (triaxdem convention) during preparation; -1: the test's
VERSION = args.get('version', '')
if LAW not in ('linear', 'hertz'):
    raise SystemExit('law must be linear or hertz')

# ---------------------------------------------------------------- physical parameters
R = 1e-3            # ball radius (m), diameter 2 mm
RHO = 2500.0        # kg/m3, no density scaling
RBAR = R / 2        # triaxdem's Rbar = r1 r2/(r1+r2)
E_TRIAX = 1e8       # triaxdem emod_Pa
KN_LIN = math.pi * E_TRIAX * R / 2      # triaxdem linear kn between equal balls = 1.5708e5 N/m
KRATIO = 1.5        # triaxdem kn/ks
EPS_END = 0.15
SOLID_CLOUD = 0.28  # solid fraction of the initial random cloud

if LAW == 'linear':
    MU_S, MU_R = 0.4, 0.04                 # triaxdem convention (generating values)
    YOUNG = KN_LIN / R                     # YADE kn = E r for equal spheres -> pi E_triax / 2
    POISSON = 1.0 / KRATIO                 # YADE ks = poisson kn
    ALPHA_KR = RBAR ** 2 / (R * R)         # YADE kr = alphaKr ks r^2 = ks Rbar^2 -> 0.25
    ETA_ROLL = MU_R * RBAR / R             # YADE cap etaRoll r Fn = mu_r Rbar Fn -> 0.02
else:
    MU_S, MU_R = 0.3, 0.02
    ESTAR = 3.0e9                          # Hertz effective modulus E/(2(1-v^2))
    POISSON = 0.5                          # Mindlin ks/kt = 2(1-v)/(2-v) = 1/1.5 = triaxdem's ks/kt
    YOUNG = ESTAR * 2 * (1 - POISSON ** 2)
    ETA_ROLL = MU_R * RBAR / R             # YADE maxBendPl = eta (r1+r2)/2 -> cap eta r Fn
    # constant rolling stiffness: triaxdem's kr = ks Rbar^2 with ks = kt/1.5 at the mean contact force of a
    # 200 kPa assembly, <Fn> = 4 pi r^2 p / (Z phi) with Z = 5, phi = 0.62
    FREF = 4 * math.pi * R * R * 2e5 / (5 * 0.62)
    KNO = 4.0 / 3.0 * ESTAR * math.sqrt(R / 2)
    UREF = (FREF / KNO) ** (2.0 / 3.0)
    KROT = 1.5 * KNO * math.sqrt(UREF) / KRATIO * RBAR ** 2
    # triaxdem hertz_overlap = delta_ref / r with kn delta^1.5/delta_ref^0.5 = 4/3 E* sqrt(r/2) delta^1.5
    HERTZ_OVERLAP = (KN_LIN / KNO) ** 2 / R

if PREP_MUR < 0:
    PREP_MUR = MU_R

CLOUD = {}

# ---------------------------------------------------------------- helpers
from yade import pack, utils

sys.path.insert(0, os.path.dirname(os.path.abspath(sys.argv[0])))  # yade -x runs the script with its path in argv[0]
from yade_curves import take_rows, debian_version, write_csv


def log(*a):
    print('[%s %s s%d] ' % (time.strftime('%H:%M:%S'), LAW, SEED) + ' '.join(str(x) for x in a), flush=True)


def stress_compr():
    """Contact (Love-Weber) stress, compression positive (utils.getStress is tension positive)."""
    return -1.0 * utils.getStress()


def make_material(mu):
    eta = max(PREP_MUR * RBAR / R, 1e-9)   # YADE applies no rolling cap at all when the cap is 0
    if LAW == 'linear':
        return CohFrictMat(young=YOUNG, poisson=POISSON, density=RHO, frictionAngle=math.atan(mu),
                           isCohesive=False, momentRotationLaw=True, alphaKr=ALPHA_KR, etaRoll=eta,
                           alphaKtw=0.0, etaTwist=0.0, label='balls')
    return FrictMat(young=YOUNG, poisson=POISSON, density=RHO, frictionAngle=math.atan(mu), label='balls')


def set_friction(mu):
    """Test friction and rolling cap, for new (material / Ip2) and existing (phys) contacts."""
    O.materials[0].frictionAngle = math.atan(mu)
    if LAW == 'linear':
        O.materials[0].etaRoll = ETA_ROLL
    else:
        IP2.eta = ETA_ROLL
    for i in O.interactions:
        if i.isReal:
            i.phys.tangensOfFrictionAngle = mu
            if LAW == 'linear':
                i.phys.maxRollPl = ETA_ROLL * R
            else:
                i.phys.maxBendPl = ETA_ROLL * R


def build(sigma3):
    O.reset()
    O.periodic = True
    mat = O.materials.append(make_material(PREP_MU))
    # makeCloud's random sequential insertion may give up before NBALLS at SOLID_CLOUD (it does for seed 2
    # with 1000 balls): then the cloud is retried at a lower solid fraction (recorded in the header)
    for frac in (SOLID_CLOUD, 0.26, 0.24, 0.22, 0.2):
        L = (NBALLS * 4.0 / 3.0 * math.pi * R ** 3 / frac) ** (1.0 / 3.0)
        sp = pack.SpherePack()
        n = sp.makeCloud((0, 0, 0), (L, L, L), rMean=R, rRelFuzz=0.0, num=NBALLS, periodic=True, seed=SEED)
        if n == NBALLS:
            break
    if n != NBALLS:
        raise SystemExit('makeCloud placed %d balls, not %d' % (n, NBALLS))
    CLOUD[sigma3] = frac
    sp.toSimulation(material=mat)
    if LAW == 'linear':
        ig = Ig2_Sphere_Sphere_ScGeom6D()
        ip = Ip2_CohFrictMat_CohFrictMat_CohFrictPhys()
        law = Law2_ScGeom6D_CohFrictPhys_CohesionMoment(useIncrementalForm=True, always_use_moment_law=True)
    else:
        ig = Ig2_Sphere_Sphere_ScGeom()
        ip = Ip2_FrictMat_FrictMat_MindlinPhys(krot=KROT, ktwist=0.0, eta=max(PREP_MUR * RBAR / R, 1e-9))
        law = Law2_ScGeom_MindlinPhys_Mindlin(includeMoment=True)
    global IP2
    IP2 = ip
    s3 = sigma3 * 1e3
    O.engines = [
        ForceResetter(),
        InsertionSortCollider([Bo1_Sphere_Aabb()]),
        InteractionLoop([ig], [ip], [law]),
        GlobalStiffnessTimeStepper(timestepSafetyCoefficient=0.5, timeStepUpdateInterval=50, label='ts'),
        NewtonIntegrator(damping=DAMPING),
        PyRunner(iterPeriod=1, command='servo()', label='servoer', initRun=True),
        PyRunner(iterPeriod=1, command='record()', label='recorder', dead=True),
    ]
    O.dt = 0.5 * utils.PWaveTimeStep()
    srv.update(T=T_SERVO_COMPACT, mask=(1, 1, 1), s3=s3, rate=0.0, vmax=2.0, integ=[0.0, 0.0, 0.0], Mit=-10**9)


# ---------------------------------------------------------------- stress servo on the cell's velocity gradient
# Each step: for a stress-controlled axis i, velGrad_ii = clamp(Ki err + integral, +-vmax) with
# err = (sigma_ii - sigma3) / M_i, M_i the affine modulus (1/V) sum_c kn l^2 n_i^4 (re-evaluated every 200
# steps; it over-estimates the true modulus, which keeps the loop stable), Ki = 1 / (T_SERVO dt); the
# integral term (time constant TI_SERVO x T_SERVO) removes the lag while the specimen dilates under shear.
# A strain-controlled axis gets velGrad_ii = -rate.
T_SERVO = 5.0       # re-equilibration and shear
T_SERVO_COMPACT = 40.0   # compaction from the cloud (T = 5 dt chatters at jamming with Hertz contacts)
TI_SERVO = 10.0
srv = dict(T=T_SERVO_COMPACT, mask=(1, 1, 1), s3=0.0, rate=0.0, vmax=1.0, M=(1.0, 1.0, 1.0), integ=[0.0, 0.0, 0.0], Mit=-10**9)


def affine_modulus():
    M = [0.0, 0.0, 0.0]
    H = O.cell.hSize
    for I in O.interactions:
        if not I.isReal:
            continue
        b1, b2 = O.bodies[I.id1].state.pos, O.bodies[I.id2].state.pos
        l = b2 + H * Vector3(I.cellDist[0], I.cellDist[1], I.cellDist[2]) - b1
        L2 = l.squaredNorm()
        n = I.geom.normal
        for i in range(3):
            M[i] += I.phys.kn * L2 * n[i] ** 4
    V = O.cell.volume
    return tuple(M[i] / V for i in range(3))


def servo():
    s3 = srv['s3']
    if O.iter - srv['Mit'] >= 500:
        srv['M'] = tuple(max(m, 20.0 * s3) for m in affine_modulus())
        srv['Mit'] = O.iter
    s = stress_compr()
    vg = [0.0, 0.0, 0.0]
    dt = O.dt
    for i in range(3):
        if srv['mask'][i]:
            T = srv['T']
            x = (s[i, i] - s3) / srv['M'][i] / (T * dt)
            if abs(s[i, i] - s3) < 0.2 * s3:
                srv['integ'][i] += x * dt / (TI_SERVO * T * dt)
            v = x + srv['integ'][i]
            vg[i] = max(-srv['vmax'], min(srv['vmax'], v))
        else:
            vg[i] = -srv['rate']
    O.cell.velGrad = Matrix3(vg[0], 0, 0, 0, vg[1], 0, 0, 0, vg[2])


def solid_volume():
    return sum(4.0 / 3.0 * math.pi * b.shape.radius ** 3 for b in O.bodies)


def equilibrate(sigma3, what, tol_unb=1e-3, tol_s=5e-3, max_iter=2000000, chunk=2000):
    s3 = sigma3 * 1e3
    it0 = O.iter
    while True:
        O.run(chunk, True)
        s = stress_compr()
        err = max(abs(s[k, k] - s3) for k in range(3)) / s3
        unb = utils.unbalancedForce()
        if (O.iter - it0) % (50 * chunk) == 0:
            log('  %s it %d dt %.3g unb %.3g stress err %.3g e %.4f' %
                (what, O.iter, O.dt, unb, err, O.cell.volume / VS - 1))
        if unb < tol_unb and err < tol_s:
            return
        if O.iter - it0 > max_iter:
            log('  WARNING %s not converged: unb %.3g err %.3g' % (what, unb, err))
            return


rows = []
state = {}


def record():
    st = state
    Lz = O.cell.hSize[2, 2]
    eps = (st['Lz0'] - Lz) / st['Lz0']
    epsv = (st['V0'] - O.cell.volume) / st['V0']
    s = stress_compr()
    q = s[2, 2] - 0.5 * (s[0, 0] + s[1, 1])
    lat = 0.5 * (s[0, 0] + s[1, 1])
    cur = (eps, q, epsv, lat)
    if take_rows(st, cur, rows):
        O.pause()


summary = []
t_all = time.time()
for sigma3 in PRESSURES:
    t0 = time.time()
    build(sigma3)
    VS = solid_volume()
    log('sigma3 %g kPa: cloud of %d balls, cell %.4g mm, compaction (prep friction %g, rolling %g)' %
        (sigma3, len(O.bodies), O.cell.hSize[0, 0] * 1e3, PREP_MU, PREP_MUR))
    equilibrate(sigma3, 'compaction')
    log('  compacted: it %d e %.4f' % (O.iter, O.cell.volume / VS - 1))
    set_friction(MU_S)
    srv['vmax'] = 0.5
    srv['T'] = T_SERVO
    equilibrate(sigma3, 're-equilibration', chunk=1000)
    e0 = O.cell.volume / VS - 1
    nc = sum(1 for i in O.interactions if i.isReal)
    zc = 2.0 * nc / len(O.bodies)
    log('  start of shear: it %d e %.4f Z %.3f dt %.3g' % (O.iter, e0, zc, O.dt))
    # drained shear: z strain-controlled (velocity gradient = rate), x, y at sigma3
    s3 = sigma3 * 1e3
    rate = INERTIAL / (2 * R * math.sqrt(RHO / s3))
    srv.update(mask=(1, 1, 0), rate=rate, vmax=10 * rate)
    state.clear()
    state.update(Lz0=O.cell.hSize[2, 2], V0=O.cell.volume, sigma3=sigma3, e0=e0, k=0)
    recorder.dead = False
    it0 = O.iter
    O.run()
    O.wait()
    recorder.dead = True
    wall = time.time() - t0
    qs = [r[2] for r in rows if r[0] == sigma3]
    summary.append((sigma3, e0, zc, rate, O.iter - it0, wall, state.get('laterr', 0), max(qs)))
    log('  done: %d shear steps, q_peak %.1f kPa (q/s3 %.3f), max lateral stress error %.3g, wall %.0f s' %
        (O.iter - it0, max(qs), max(qs) / sigma3, state.get('laterr', 0), wall))

# ---------------------------------------------------------------- output
deb = debian_version()
import yade.config
hdr = []
hdr.append('# generator: tests/data/crosscode/yade_peri_triax.py (YADE periodic-cell drained triaxial test)')
hdr.append('# yade: %s (yade.config.version %s, Debian package yade %s)' % (VERSION or 'yade', yade.config.version, deb))
hdr.append('# date: %s' % time.strftime('%Y-%m-%d %H:%M:%S %Z'))
hdr.append('# law: %s; material: %s; seed: %d; balls: %d; monodisperse d = 2 mm; density %g kg/m3 (no density scaling)' %
           (LAW, MATNAME, SEED, NBALLS, RHO))
if LAW == 'linear':
    hdr.append('# YADE: CohFrictMat(young=%.6g, poisson=%.6g, frictionAngle=atan(%g), momentRotationLaw=True, alphaKr=%.6g, etaRoll=%.6g, alphaKtw=0, isCohesive=False) + Ip2_CohFrictMat_CohFrictMat_CohFrictPhys + Law2_ScGeom6D_CohFrictPhys_CohesionMoment(useIncrementalForm=True, always_use_moment_law=True)' %
               (YOUNG, POISSON, MU_S, ALPHA_KR, ETA_ROLL))
    hdr.append('# contact: kn = %.6g N/m, ks = %.6g N/m, kr = %.6g N m/rad, rolling cap = etaRoll r Fn = %.6g Fn (m)' %
               (YOUNG * R, POISSON * YOUNG * R, ALPHA_KR * POISSON * YOUNG * R * R * R, ETA_ROLL * R))
    hdr.append('# triaxdem-equivalent (rrlinear): mu_s = %g, mu_r = %g, emod_Pa = %g, kratio = %g, kr ratio YADE/triaxdem = 1' %
               (MU_S, MU_R, E_TRIAX, KRATIO))
else:
    hdr.append('# YADE: FrictMat(young=%.6g, poisson=%g, frictionAngle=atan(%g)) + Ip2_FrictMat_FrictMat_MindlinPhys(krot=%.6g, ktwist=0, eta=%.6g) + Law2_ScGeom_MindlinPhys_Mindlin(includeMoment=True); no viscous damping (betan=betas=0)' %
               (YOUNG, POISSON, MU_S, KROT, ETA_ROLL))
    hdr.append('# contact: Hertz E* = %.6g Pa, Fn = kno un^1.5, kno = 4/3 E* sqrt(r/2) = %.6g, ks = kso un^0.5 (ks/kt = 2(1-v)/(2-v) = %.4g), kr = krot = %.6g N m/rad (constant; = triaxdem ks Rbar^2 at Fn = %.3g N), rolling cap = eta r Fn = %.6g Fn (m)' %
               (ESTAR, KNO, 2 * (1 - POISSON) / (2 - POISSON), KROT, FREF, ETA_ROLL * R))
    hdr.append('# triaxdem-equivalent: mu_s = %g, mu_r = %g, emod_Pa = %g, kratio = %g, hertz_overlap = %.6g (delta_ref/r; E_H = %.6g)' %
               (MU_S, MU_R, E_TRIAX, KRATIO, HERTZ_OVERLAP, ESTAR))
hdr.append('# preparation: makeCloud(periodic, solid fraction %g or less if it cannot place all balls, seed %d), a fresh specimen per pressure; isotropic compaction to sigma3 by the same velGrad stress servo with friction %g and rolling friction %g (triaxdem convention), then friction %g and the test rolling cap set on all contacts, re-equilibrated (unbalanced force < 1e-3, stress within 0.5%%)' %
           (SOLID_CLOUD, SEED, PREP_MU, PREP_MUR, MU_S))
hdr.append('# shear: cell velocity gradient, z at constant velocity gradient rate = I / (d sqrt(rho/sigma3)), x and y stress-controlled at sigma3 by a PI servo on O.cell.velGrad (contact stress, affine modulus; T=5 dt, Ti=10 T; T=40 dt in the compaction); inertial number I = %g; NewtonIntegrator local damping %g; GlobalStiffnessTimeStepper safety 0.5; to %g%% axial strain' %
           (INERTIAL, DAMPING, EPS_END * 100))
hdr.append('# records: every 0.02% axial strain to 1%, every 0.1% to 15% (linear interpolation between steps); eps_a = (Lz0 - Lz)/Lz0 from the start of shear; q = s_zz - (s_xx+s_yy)/2 of the contact stress (-utils.getStress()); eps_v = (V0 - V)/V0; void_ratio = V_cell/V_solid - 1 at the start of shear')
for s in summary:
    hdr.append('# test sigma3 %g kPa: cloud solid fraction %g, e0 %.4f, Z %.3f, rate %.4g 1/s, %d shear steps, q_peak/sigma3 %.3f, max |lateral stress - sigma3|/sigma3 at records %.3g, wall %.0f s' %
               (s[0], CLOUD[s[0]], s[1], s[2], s[3], s[4], s[7] / s[0], s[6], s[5]))
hdr.append('# total wall time %.0f s (one core)' % (time.time() - t_all))
write_csv(OUT, hdr, rows, MATNAME)
log('wrote', OUT, len(rows), 'rows')
sys.exit(0)
