# -*- coding: utf-8 -*-
"""Drained triaxial tests on a cuboid between six rigid walls with YADE's TriaxialStressController (cross-code
test data with a boundary for triaxdem's `walls` reference test).

Run:  yade -j1 -n -x yade_walled_triax.py seed=1 n=1000 pressures=100,200,300 mat=wall out=walled_seed1.csv
Optional key=value arguments: inertial=1e-3 damping=0.5 prep_mu=0.1 version=...

Each pressure uses its own, freshly prepared specimen from the same seed: a random loose cloud in a cube, the six
frictionless walls moved by the controller to an isotropic sigma3 with the preparation friction prep_mu (rolling
cap as the test's), then the test friction set on every ball-ball contact, re-equilibrated, and sheared: the top
and bottom walls at a constant strain rate, the four lateral walls held at sigma3 by the controller, to 15% axial
strain. Everything is measured at the walls, as YADE's own triaxial examples and most walled DEM studies do:
sigma_ii = the mean normal force on the two walls normal to i over the current face area (from the walls'
positions), eps_a = (Lz0 - Lz)/Lz0, eps_v = (V0 - V)/V0 with V = Lx Ly Lz.

The ball-ball law is yade_peri_triax.py's linear law (CohFrictMat, kn = E r, ks = poisson kn, rolling stiffness
and cap), there derived as triaxdem's rrlinear with emod 1e8 Pa, kn/ks 1.5, mu_s 0.4, mu_r 0.04. The walls are
CohFrictMat without friction or rolling moment, 1e4 times stiffer than the balls, so that their stiffness with a
ball is triaxdem's (2 E r); it is measured in the run and written in the header.
"""
import sys, math, time, os

args = dict(a.split('=', 1) for a in sys.argv[1:] if '=' in a)
SEED = int(args.get('seed', '1'))
NBALLS = int(args.get('n', '1000'))
PRESSURES = [float(p) for p in args.get('pressures', '100,200,300').split(',')]
MATNAME = args.get('mat', 'wall')
OUT = args.get('out', 'walled_seed%d.csv' % SEED)
INERTIAL = float(args.get('inertial', '1e-3'))
DAMPING = float(args.get('damping', '0.5'))
PREP_MU = float(args.get('prep_mu', '0.1'))
VERSION = args.get('version', '')

R = 1e-3
RHO = 2500.0
RBAR = R / 2
E_TRIAX = 1e8
KN_LIN = math.pi * E_TRIAX * R / 2
KRATIO = 1.5
EPS_END = 0.15
SOLID_CLOUD = 0.25
MU_S, MU_R = 0.4, 0.04
YOUNG = KN_LIN / R
POISSON = 1.0 / KRATIO
ALPHA_KR = RBAR ** 2 / (R * R)
ETA_ROLL = MU_R * RBAR / R
# YADE's ball-wall kn = 2 Ew E r / (Ew + E) (measured: E r with Ew = E); triaxdem's is pi E_triax r = 2 E r (a wall
# counts as a ball of the same radius against a flat, kernels/contact/contact_law.hpp): stiff walls take YADE to 0.9999 of it.
WALL_YOUNG = 1e4 * YOUNG

from yade import pack, utils

sys.path.insert(0, os.path.dirname(os.path.abspath(sys.argv[0])))  # yade -x runs the script with its path in argv[0]
from yade_curves import take_rows, debian_version, write_csv


def log(*a):
    print('[%s walled s%d] ' % (time.strftime('%H:%M:%S'), SEED) + ' '.join(str(x) for x in a), flush=True)


def box():
    """Lengths (x, y, z) between the walls' inner faces (thickness 0: their centres)."""
    p = [O.bodies[i].state.pos for i in range(6)]
    return [p[2 * d + 1][d] - p[2 * d][d] for d in range(3)]


def wall_stress():
    """sigma_ii at the walls, compression positive: mean |normal force| of the pair over the face area."""
    L = box()
    s = []
    for d in range(3):
        f = 0.5 * (abs(O.forces.f(2 * d)[d]) + abs(O.forces.f(2 * d + 1)[d]))
        s.append(f / (L[(d + 1) % 3] * L[(d + 2) % 3]))
    return s


def build(sigma3):
    O.reset()
    balls = O.materials.append(CohFrictMat(young=YOUNG, poisson=POISSON, density=RHO, frictionAngle=math.atan(PREP_MU),
                                           isCohesive=False, momentRotationLaw=True, alphaKr=ALPHA_KR, etaRoll=ETA_ROLL,
                                           alphaKtw=0.0, etaTwist=0.0, label='balls'))
    walls = O.materials.append(CohFrictMat(young=WALL_YOUNG, poisson=POISSON, density=0, frictionAngle=0.0,
                                           isCohesive=False, momentRotationLaw=False, label='walls'))
    L = (NBALLS * 4.0 / 3.0 * math.pi * R ** 3 / SOLID_CLOUD) ** (1.0 / 3.0)
    mn, mx = Vector3(0, 0, 0), Vector3(L, L, L)
    O.bodies.append(utils.aabbWalls([mn, mx], thickness=0, material=walls))
    sp = pack.SpherePack()
    n = sp.makeCloud(mn, mx, rMean=R, rRelFuzz=0.0, num=NBALLS, periodic=False, seed=SEED)
    if n != NBALLS:
        raise SystemExit('makeCloud placed %d balls, not %d' % (n, NBALLS))
    sp.toSimulation(material=balls)
    s3 = sigma3 * 1e3
    global TRIAX
    TRIAX = TriaxialStressController(thickness=0, stressMask=7, internalCompaction=False, goal1=-s3, goal2=-s3,
                                     goal3=-s3, max_vel=0.05, label='triax')
    O.engines = [
        ForceResetter(),
        InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Box_Aabb()]),
        InteractionLoop([Ig2_Sphere_Sphere_ScGeom6D(), Ig2_Box_Sphere_ScGeom6D()],
                        [Ip2_CohFrictMat_CohFrictMat_CohFrictPhys()],
                        [Law2_ScGeom6D_CohFrictPhys_CohesionMoment(useIncrementalForm=True, always_use_moment_law=True)]),
        GlobalStiffnessTimeStepper(timestepSafetyCoefficient=0.5, timeStepUpdateInterval=50, label='ts'),
        TRIAX,
        NewtonIntegrator(damping=DAMPING),
        PyRunner(iterPeriod=1, command='record()', label='recorder', dead=True),
    ]
    O.dt = 0.5 * utils.PWaveTimeStep()


def solid_volume():
    return sum(4.0 / 3.0 * math.pi * b.shape.radius ** 3 for b in O.bodies if isinstance(b.shape, Sphere))


def equilibrate(sigma3, what, tol_unb=1e-3, tol_s=5e-3, max_iter=2000000, chunk=1000):
    s3 = sigma3 * 1e3
    it0 = O.iter
    while True:
        O.run(chunk, True)
        s = wall_stress()
        err = max(abs(x - s3) for x in s) / s3
        unb = utils.unbalancedForce()
        if (O.iter - it0) % (20 * chunk) == 0:
            L = box()
            log('  %s it %d dt %.3g unb %.3g stress err %.3g e %.4f' % (what, O.iter, O.dt, unb, err, L[0] * L[1] * L[2] / VS - 1))
        if unb < tol_unb and err < tol_s:
            return
        if O.iter - it0 > max_iter:
            log('  WARNING %s not converged: unb %.3g err %.3g' % (what, unb, err))
            return


def wall_kn():
    """Normal stiffness of the ball-wall contacts (N/m), the mean over those present."""
    k = [i.phys.kn for i in O.interactions if i.isReal and min(i.id1, i.id2) < 6]
    return sum(k) / len(k) if k else float('nan')


rows = []
state = {}


def record():
    st = state
    L = box()
    V = L[0] * L[1] * L[2]
    eps = (st['Lz0'] - L[2]) / st['Lz0']
    epsv = (st['V0'] - V) / st['V0']
    s = wall_stress()
    q = s[2] - 0.5 * (s[0] + s[1])
    lat = 0.5 * (s[0] + s[1])
    cur = (eps, q, epsv, lat)
    if take_rows(st, cur, rows):
        O.pause()


summary = []
t_all = time.time()
for sigma3 in PRESSURES:
    t0 = time.time()
    build(sigma3)
    VS = solid_volume()
    log('sigma3 %g kPa: cloud of %d balls in a cube of %.4g mm, compaction (prep friction %g)' %
        (sigma3, NBALLS, box()[0] * 1e3, PREP_MU))
    equilibrate(sigma3, 'compaction')
    for i in O.interactions:  # the test friction on the ball-ball contacts (walls stay frictionless)
        if i.isReal and min(i.id1, i.id2) >= 6:
            i.phys.tangensOfFrictionAngle = MU_S
    O.materials[0].frictionAngle = math.atan(MU_S)
    equilibrate(sigma3, 're-equilibration')
    L = box()
    e0 = L[0] * L[1] * L[2] / VS - 1
    zc = 2.0 * sum(1 for i in O.interactions if i.isReal and min(i.id1, i.id2) >= 6) / NBALLS
    kw = wall_kn()
    log('  start of shear: it %d e %.4f Z %.3f dt %.3g wall kn %.4g' % (O.iter, e0, zc, O.dt, kw))
    s3 = sigma3 * 1e3
    rate = INERTIAL / (2 * R * math.sqrt(RHO / s3))
    TRIAX.stressMask = 3           # x and y at sigma3, z strain-controlled
    TRIAX.goal3 = -rate            # compression
    state.clear()
    state.update(Lz0=L[2], V0=L[0] * L[1] * L[2], sigma3=sigma3, e0=e0, k=0)
    recorder.dead = False
    it0 = O.iter
    O.run()
    O.wait()
    recorder.dead = True
    wall = time.time() - t0
    qs = [r[2] for r in rows if r[0] == sigma3]
    summary.append((sigma3, e0, zc, rate, O.iter - it0, wall, state.get('laterr', 0), max(qs), kw))
    log('  done: %d shear steps, q_peak %.1f kPa (q/s3 %.3f), max lateral stress error %.3g, wall %.0f s' %
        (O.iter - it0, max(qs), max(qs) / sigma3, state.get('laterr', 0), wall))

deb = debian_version()
import yade.config
hdr = []
hdr.append('# generator: tests/data/crosscode/yade_walled_triax.py (YADE drained triaxial test on a cuboid between six rigid walls, TriaxialStressController)')
hdr.append('# yade: %s (yade.config.version %s, Debian package yade %s)' % (VERSION or 'yade', yade.config.version, deb))
hdr.append('# date: %s' % time.strftime('%Y-%m-%d %H:%M:%S %Z'))
hdr.append('# law: linear; material: %s; seed: %d; balls: %d; monodisperse d = 2 mm; density %g kg/m3 (no density scaling)' %
           (MATNAME, SEED, NBALLS, RHO))
hdr.append('# YADE balls: CohFrictMat(young=%.6g, poisson=%.6g, frictionAngle=atan(%g), momentRotationLaw=True, alphaKr=%.6g, etaRoll=%.6g, alphaKtw=0, isCohesive=False); walls: CohFrictMat(young=%.6g, frictionAngle=0, momentRotationLaw=False); Ip2_CohFrictMat_CohFrictMat_CohFrictPhys + Law2_ScGeom6D_CohFrictPhys_CohesionMoment(useIncrementalForm=True, always_use_moment_law=True)' %
           (YOUNG, POISSON, MU_S, ALPHA_KR, ETA_ROLL, WALL_YOUNG))
hdr.append('# contact: ball-ball kn = %.6g N/m, ks = %.6g N/m, kr = %.6g N m/rad, rolling cap = etaRoll r Fn = %.6g Fn (m); ball-wall kn measured %.6g N/m, frictionless' %
           (YOUNG * R, POISSON * YOUNG * R, ALPHA_KR * POISSON * YOUNG * R * R * R, ETA_ROLL * R, summary[0][8]))
hdr.append('# triaxdem-equivalent (rrlinear): mu_s = %g, mu_r = %g, emod_Pa = %g, kratio = %g; frictionless walls' %
           (MU_S, MU_R, E_TRIAX, KRATIO))
hdr.append('# preparation: makeCloud in a cube (solid fraction %g, seed %d), a fresh specimen per pressure; TriaxialStressController(internalCompaction=False, max_vel=0.05) moves the six walls to an isotropic sigma3 with ball friction %g; then friction %g on all ball-ball contacts, re-equilibrated (unbalanced force < 1e-3, wall stresses within 0.5%%)' %
           (SOLID_CLOUD, SEED, PREP_MU, MU_S))
hdr.append('# shear: stressMask=3 (x, y walls at sigma3), z walls at the strain rate I / (d sqrt(rho/sigma3)), I = %g; NewtonIntegrator local damping %g; GlobalStiffnessTimeStepper safety 0.5; to %g%% axial strain' %
           (INERTIAL, DAMPING, EPS_END * 100))
hdr.append('# records: every 0.02% axial strain to 1%, every 0.1% to 15% (linear interpolation between steps); stresses at the walls: mean normal force of the two walls of an axis over the current face area; q = s_zz - (s_xx+s_yy)/2; eps_a = (Lz0 - Lz)/Lz0 from the start of shear; eps_v = (V0 - V)/V0, V = Lx Ly Lz between the walls; void_ratio = V/V_solid - 1 at the start of shear')
for s in summary:
    hdr.append('# test sigma3 %g kPa: e0 %.4f, Z %.3f, rate %.4g 1/s, %d shear steps, q_peak/sigma3 %.3f, max |lateral stress - sigma3|/sigma3 at records %.3g, wall %.0f s' %
               (s[0], s[1], s[2], s[3], s[4], s[7] / s[0], s[6], s[5]))
hdr.append('# total wall time %.0f s (one core)' % (time.time() - t_all))
write_csv(OUT, hdr, rows, MATNAME, 'area_corrected', NBALLS)  # q over the current face area
log('wrote', OUT, len(rows), 'rows')
sys.exit(0)
