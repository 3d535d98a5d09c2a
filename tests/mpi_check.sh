#!/usr/bin/env bash
# The jobs spread over MPI ranks (host/util/ranks.hpp) against the same jobs on one machine, in outputs compared value
# by value (tools/compare_runs.py: every CSV and checkpoint value; times and provenance left out) and reports byte
# by byte:
#  1. a tiny study of two membrane cases on 3 ranks (mpirun -n 3 --oversubscribe --enable-recovery), one of its two
#     working ranks killed part way: its case must run again on the other and end as the local run's;
#  2. a second study into the folder the first holds: refused, naming the holder;
#  3. a tiny calibration and 4. a tiny diagnosis on 3 ranks;
#  5. a rank that cannot see the output folder (its own empty file system mounted over it, where this machine lets
#     `unshare` do that): refused on every rank, naming the rank.
#   tests/mpi_check.sh BUILD_DIR [WORK_DIR]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="$(realpath "$1")"; work="$(realpath -m "${2:-$build/mpi_check}")"
tdem="$build/triaxdem"
py=python3; [ -x /usr/bin/python3 ] && py=/usr/bin/python3
compare="$py $root/tools/compare_runs.py"
command -v mpirun > /dev/null || { echo "mpi_check: no mpirun (Debian: openmpi-bin)" >&2; exit 1; }
. "$root/scripts/script_folders.sh"
fresh_folder mpi_check "$work"; cd "$work"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMP_PROC_BIND=false OMP_NUM_THREADS=1
# Seconds without word from a rank before its piece goes elsewhere: short, so that the killed rank is seen at once.
export TRIAXDEM_RANK_TIMEOUT_S=3
mpi=(mpirun -n 3 --oversubscribe -x OMP_PROC_BIND -x OMP_NUM_THREADS -x TRIAXDEM_RANK_TIMEOUT_S)
fail() { echo "mpi_check: FAILED: $*" >&2; exit 1; }
same() {  # same LOCAL_FOLDER MPI_FOLDER: every shared CSV identical
  $compare "$1" "$2" > "$work/compare.txt" 2>&1 || { cat "$work/compare.txt"; fail "$2 differs from $1"; }
}

# 1. The study: two cases of the tiny membrane test (2 layers, to 1% axial strain).
mkdir -p configs
for p in 100 200; do
  sed -e "s/^sigma3_kPa = .*/sigma3_kPa = $p/" -e "s/^axial_strain_end_pct = .*/axial_strain_end_pct = 1.0/" \
      -e "s/^record_every_pct = .*/record_every_pct = 0.05/" -e "s/^layers = .*/layers = 2/" \
      "$root/tests/data/tiny_triaxial.toml" > "configs/t$p.toml"
done
"$tdem" study configs -o study_local -j 2 --threads 1 > study_local.log 2>&1 || { cat study_local.log; fail "local study"; }
"${mpi[@]}" --enable-recovery "$tdem" study configs -o study_mpi --threads 1 > study_mpi.log 2>&1 &
job=$!
# Rank 2 once both cases run (each case's log has its first lines): kill it and its case with it.
for _ in $(seq 600); do
  [ -s study_mpi/t100/log.txt ] && [ -s study_mpi/t200/log.txt ] && break
  sleep 0.1
done
victim=""
for pid in $(pgrep -f "^$tdem study configs -o study_mpi" || true); do
  tr '\0' '\n' < "/proc/$pid/environ" 2>/dev/null | grep -qx "OMPI_COMM_WORLD_RANK=2" && victim=$pid
done
[ -n "$victim" ] || { kill "$job" 2>/dev/null; cat study_mpi.log; fail "rank 2 of the study not found"; }
# 2. While the study holds its folder, a second one into it is refused.
if "${mpi[@]}" "$tdem" study configs -o study_mpi > second.log 2>&1; then fail "a second study into a held folder ran"; fi
grep -q "another run\|in use\|held\|lock" second.log || { cat second.log; fail "the second study's refusal names no holder"; }
kill -9 "$victim"
wait "$job" || { cat study_mpi.log; fail "the study with a rank killed (exit $?)"; }
grep -q "rank 2 has not answered" study_mpi.log || { cat study_mpi.log; fail "the killed rank was not reported"; }
for d in study_local study_local/t100 study_local/t200; do same "$d" "${d/study_local/study_mpi}"; done
echo "mpi_check: study on 3 ranks, rank 2 killed part way: identical to the local run"

# 3-4. Calibration and diagnosis of a tiny synthetic test (the suite's own tiny set: tests/data/hidden_effects.toml,
# one specimen, to 1%).
sed -e 's/^ensemble = .*/ensemble = 1/' -e 's/^scatter_specimens = .*/scatter_specimens = 2/' \
    -e 's/^target_axial_strain_pct = .*/target_axial_strain_pct = 1.0/' "$root/tests/data/hidden_effects.toml" > base.toml
"$tdem" synth --config base.toml -o synth.csv --extension none --seed 1 --pressures 100 > synth.log 2>&1
# Without the data's void ratio: no state match, whose packings were two thirds of each job (33 -> 10 s); the pools
# (the specimens' packing, the cell-bias check, the ensemble's runs) are the same code.
awk -F, 'BEGIN { OFS = "," } /^#/ { print; next } { print $1, $2, $3, $4, $5, $7 }' synth.csv > data.csv
head -3 data.csv | grep -q "^material,sigma3_kPa,eps_a_pct,q_kPa,eps_v_pct,specimen_balls$" || fail "data.csv's columns"
for job in calibrate diagnose; do
  args=(data.csv --config base.toml --predict none)
  "$tdem" "$job" "${args[@]}" -o "${job}_local" -j 2 > "${job}_local.log" 2>&1 || { cat "${job}_local.log"; fail "$job"; }
  "${mpi[@]}" "$tdem" "$job" "${args[@]}" -o "${job}_mpi" > "${job}_mpi.log" 2>&1 ||
    { cat "${job}_mpi.log"; fail "$job on 3 ranks"; }
  a=$(ls -d "${job}_local"/*/); b=$(ls -d "${job}_mpi"/*/)
  same "$a" "$b"
  for md in "$a"*.md; do [ -e "$md" ] && { cmp "$md" "$b$(basename "$md")" || fail "$md differs"; }; done
  grep -q "spread over 3 MPI ranks\|runs" "${job}_mpi.log"
  echo "mpi_check: $job on 3 ranks: identical to the local run"
done

# 5. A rank that does not see the output folder.
mkdir -p blind
if unshare -m --propagation private true 2> /dev/null; then
  if mpirun -n 1 --oversubscribe "$tdem" study configs -o blind : -n 1 --oversubscribe \
       unshare -m --propagation private sh -c "mount -t tmpfs none '$work/blind' && exec '$tdem' study configs -o blind" \
       > blind.log 2>&1; then
    fail "a study ran with a rank that cannot see its folder"
  fi
  grep -q "not seen by every rank (rank 1 on" blind.log || { cat blind.log; fail "the blind rank was not named"; }
  [ ! -e blind/t100 ] || fail "the refused study started a case"
  echo "mpi_check: a rank that cannot see the output folder: refused, named"
else
  echo "mpi_check: a rank that cannot see the output folder: not checked (unshare -m is not allowed here)"
fi
echo "mpi_check: passed"
