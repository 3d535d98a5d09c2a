#!/usr/bin/env bash
# Side-by-side throughput on one packing: triaxdem (OpenMP threads) against LIGGGHTS and LAMMPS (Debian
# packages, MPI ranks), each on all cores, run one after the other in this one script so that the ratios
# are taken on the same machine in the same state. Installs the peers from Debian when they are missing.
#   perf/peer_benchmark.sh                    # STEPS=2000 REPS=3 NP=$(nproc) BUILD=build PEERS="liggghts lammps"
# CONFIG: another packing config (default perf/configs/periodic_54k.toml); PEERS="": triaxdem alone (the CI's check).
# CSV=FILE: one row a code appended (date, commit, machine, cores, balls, steps, code, the median and the runs), the
# results page's file (data/results/peer_benchmark/rates.csv).
# The packing: perf/configs/periodic_54k.toml (54,872 balls of 2 mm, a jittered cubic array at a pitch of
# 0.995 d, periodic), written by triaxdem and read by the peers. The contact laws, as close as each code has:
#   triaxdem  rrlinear: kn = pi r^2 E / (2 r), ks = kn / 1.5, Coulomb mu_s 0.3, rolling spring ks R^2 capped
#             at mu_r 0.02; local damping 0.7
#   LIGGGHTS  gran model hooke/stiffness tangential history rolling_friction epsd2, the same kn, kt, mu, mu_r
#   LAMMPS    pair granular hooke + linear_history + rolling sds, the same kn, kt, mu, k_roll = kt, mu_r
# with the same time step, skin (0.2 d) and step count. Damping differs (local against viscous), which changes
# no cost. Prints particle-steps per second (median of REPS) and triaxdem's ratio to the faster peer.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
. "$root/scripts/script_folders.sh"
steps="${STEPS:-2000}"; reps="${REPS:-3}"; np="${NP:-$(nproc)}"
build="$(build_folder peer_benchmark)"; work="$(realpath -m "${WORK:-$root/runs/peer_benchmark}")"
peers="${PEERS-liggghts lammps}"
csv="${CSV:+$(realpath -m "$CSV")}"  # the script may change folder
tdem="$build/triaxdem"
[ -x "$tdem" ] || { echo "peer_benchmark: build triaxdem first ($tdem)"; exit 1; }
declare -A package=([liggghts]=liggghts [lammps]=lammps) command_of=([liggghts]=liggghts [lammps]=lmp)
missing=""
for code in $peers; do command -v "${command_of[$code]}" >/dev/null || missing+=" ${package[$code]}"; done
[ -z "$peers" ] || command -v mpirun >/dev/null || missing+=" openmpi-bin"
if [ -n "$missing" ]; then
  SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends $missing
fi
# Debian's interpreter first: python3-h5py is installed for it, not for a python3 earlier on PATH.
py=python3; [ -x /usr/bin/python3 ] && py=/usr/bin/python3
mkdir -p "$work"
cd "$work"
cfg="$(realpath "${CONFIG:-$root/perf/configs/periodic_54k.toml}")"
export OMP_PROC_BIND=spread OMP_PLACES=threads
# The packing and the time step, from triaxdem itself.
OMP_NUM_THREADS="$np" "$tdem" run "$cfg" -o "$work/packing" -n 0 --overwrite > packing.log 2>&1
dt=$(sed -n 's/.*, dt \([0-9.e+-]*\) s.*/\1/p' packing.log | head -1)
"$py" - "$work/packing/snap_000000000.h5" "$cfg" <<'PY'
import sys, h5py, tomllib
snap, cfg = sys.argv[1], sys.argv[2]
c = tomllib.load(open(cfg, "rb"))
L = [v * 1e-3 for v in c["box"]["size_mm"]]
rho = c["particles"]["density_kg_m3"]
with h5py.File(snap) as f:
    x, r = f["x"][:], f["radius"][:]
with open("packing.data", "w") as o:
    o.write(f"triaxdem packing {cfg}\n\n{len(r)} atoms\n1 atom types\n\n")
    o.write(f"0 {L[0]!r} xlo xhi\n0 {L[1]!r} ylo yhi\n0 {L[2]!r} zlo zhi\n\nAtoms\n\n")
    for i, (p, ri) in enumerate(zip(x, r)):
        o.write(f"{i + 1} 1 {2 * ri!r} {rho!r} {p[0]!r} {p[1]!r} {p[2]!r}\n")
PY
E=1.0e8; r=1.0e-3
kn=$("$py" -c "import math; print(math.pi*$r*$r*$E/(2*$r))")
kt=$("$py" -c "print($kn/1.5)")
skin=0.0004
cat > in.liggghts <<IN
atom_style granular
atom_modify map array
boundary p p p
newton off
communicate single vel yes
units si
read_data packing.data
neighbor $skin bin
neigh_modify delay 0
fix m1 all property/global kn peratomtypepair 1 $kn
fix m2 all property/global kt peratomtypepair 1 $kt
fix m3 all property/global gamman peratomtypepair 1 0.0
fix m4 all property/global gammat peratomtypepair 1 0.0
fix m5 all property/global coefficientFriction peratomtypepair 1 0.3
fix m6 all property/global coefficientRollingFriction peratomtypepair 1 0.02
pair_style gran model hooke/stiffness tangential history rolling_friction epsd2
pair_coeff * *
timestep $dt
fix integr all nve/sphere
thermo 100
run $steps
IN
cat > in.lammps <<IN
units si
atom_style sphere
boundary p p p
comm_modify vel yes
read_data packing.data
neighbor $skin bin
neigh_modify delay 0
pair_style granular
pair_coeff * * hooke $kn 0.0 tangential linear_history $kt 0.0 0.3 rolling sds $kt 0.0 0.02
timestep $dt
fix integr all nve/sphere
thermo 100
run $steps
IN
rate_of_loop() {  # particle-steps/s from "Loop time of T on P procs for N steps with M atoms"
  sed -n 's/^Loop time of \([0-9.e+-]*\) on [0-9]* procs for \([0-9]*\) steps with \([0-9]*\) atoms.*/\3 \2 \1/p' "$1" |
    tail -1 | awk '{ printf "%.4g\n", $1 * $2 / $3 }'
}
mpi="mpirun -np $np --bind-to core"
[ "$(id -u)" -ne 0 ] || mpi="$mpi --allow-run-as-root"
declare -A rates
for rep in $(seq "$reps"); do
  OMP_NUM_THREADS="$np" "$tdem" run "$cfg" -o "$work/triaxdem_run" -n "$steps" --overwrite > triaxdem.log 2>&1
  rates[triaxdem]+="$(sed -n 's/.*; \([0-9.e+]*\) particle-steps\/s.*/\1/p' triaxdem.log | tail -1) "
  for code in $peers; do
    OMP_NUM_THREADS=1 $mpi "${command_of[$code]}" -in "in.$code" -log none > "$code.log" 2>&1
    rates[$code]+="$(rate_of_loop "$code.log") "
  done
done
median() { tr ' ' '\n' | grep . | sort -g | awk '{ a[NR] = $1 } END { print a[int((NR + 1) / 2)] }'; }
balls=$(sed -n 's/^\([0-9]*\) atoms$/\1/p' packing.data)
echo "peer benchmark: $balls balls, $steps steps, dt $dt s, $np cores (triaxdem: $np OpenMP threads; peers: $np MPI ranks), median of $reps"
best=0
for code in triaxdem $peers; do
  m=$(echo "${rates[$code]}" | median)
  printf "  %-9s %8.3g particle-steps/s   (runs: %s)\n" "$code" "$m" "${rates[$code]}"
  [ "$code" = triaxdem ] && mine=$m
  [ "$code" != triaxdem ] && best=$("$py" -c "print(max($best, $m))")
done
[ -z "$peers" ] || "$py" -c "print(f'  triaxdem / faster peer: {$mine / $best:.2f}')"
if [ -n "$csv" ]; then
  . "$root/scripts/provenance.sh"
  [ -s "$csv" ] || echo "date,commit,machine,cores,balls,steps,code,median_psteps_per_s,runs" > "$csv"
  for code in triaxdem $peers; do
    echo "$(provenance_fields "$root"),$np,$balls,$steps,$code,$(echo "${rates[$code]}" | median),${rates[$code]% }" >> "$csv"
  done
fi
