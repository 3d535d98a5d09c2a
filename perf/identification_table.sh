#!/usr/bin/env bash
# The identification table (issue 63, item 3) gathered a seed at a time inside a time budget, so that its ~130 cases
# (about 5 hours on 2 cores) fill over several sittings: each level's rows in OUT/<level>.csv, each row with the
# commit that ran it and its seconds; a seed whose cases are all there is not run again. Then tools/sweep_table.py's
# table over what is done (Markdown on stdout), and what is left.
#   perf/identification_table.sh   # LEVELS="precise lab" HIDDEN_SEEDS="1 2 3 4 5 6" NULL_SEEDS="7 ... 30" JOBS=2
#                                  # BUDGET=3600 BUILD=build OUT=data/sweeps/identification CASE_S=150 PLAN=0
# A seed of HIDDEN_SEEDS runs nothing hidden and every extension in one perf/hidden_sweep (its cases share the seed's
# data specimens and are compared with its null case); a seed of NULL_SEEDS runs the null case alone. A seed is
# started only where the budget leaves its cases' time (CASE_S a case until the rows give their own mean). PLAN=1
# prints the plan and the table, and runs nothing. SWEEP_ARGS: more of hidden_sweep's options (the scripts' check:
# a tiny config). Rows of another commit are kept and counted apart in the plan: the table should be one program's.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
. "$root/scripts/script_folders.sh"
build="$(build_folder identification_table)"; out="$(realpath -m "${OUT:-$root/data/sweeps/identification}")"
levels="${LEVELS:-precise lab}"; hidden_seeds="${HIDDEN_SEEDS-1 2 3 4 5 6}"; null_seeds="${NULL_SEEDS-$(seq -s ' ' 7 30)}"
jobs="${JOBS:-2}"; budget="${BUDGET:-3600}"; case_s="${CASE_S:-150}"; plan="${PLAN:-0}"
sweep="$build/perf/hidden_sweep"
[ -x "$sweep" ] || { echo "identification_table: build perf/hidden_sweep first ($sweep)"; exit 1; }
py=python3; [ -x /usr/bin/python3 ] && py=/usr/bin/python3
commit="$(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo unknown)"
git -C "$root" diff --quiet HEAD -- host kernels perf 2>/dev/null || commit="$commit+"  # uncommitted code changes
# Every extension the sweep knows, from its own --help (the choices of --hidden), one space apart (xargs): --hidden
# then gets no empty entry.
extensions="$("$sweep" --help | sed -n 's/.*--hidden.*{\(.*\)}.*/\1/p' | tr ',' ' ' | sed 's/\bnone\b//' | xargs)"
[ -n "$extensions" ] || { echo "identification_table: could not read the extensions from $sweep --help"; exit 1; }
mkdir -p "$out"
noise() { [ "$1" = precise ] && echo 0 || echo 1; }
# cases LEVEL SEED: the hidden effects a seed runs.
cases() { if [[ " $hidden_seeds " == *" $2 "* ]]; then echo "none $extensions"; else echo none; fi; }
# done_rows LEVEL SEED: how many of the seed's cases the level's file holds (any commit).
done_rows() {
  [ -f "$out/$1.csv" ] || { echo 0; return; }
  awk -F, -v s="$2" 'NR > 1 && $3 == s' "$out/$1.csv" | wc -l
}
all_rows() { cat "$out"/*.csv 2>/dev/null || true; }
# The mean seconds of a case in the rows so far (this machine's), or CASE_S.
mean_case() {
  all_rows | awk -F, '$1 == "hidden" { for (i = 1; i <= NF; i++) if ($i == "seconds") c = i; next }
    c && $c > 0 { s += $c; n++ } END { if (n) printf "%d", s / n; else print '"$case_s"' }'
}
units=(); left_cases=0
for level in $levels; do
  for seed in $hidden_seeds $null_seeds; do
    n=$(wc -w <<< "$(cases "$level" "$seed")")
    [ "$(done_rows "$level" "$seed")" -ge "$n" ] && continue
    units+=("$level:$seed:$n"); left_cases=$((left_cases + n))
  done
done
each=$(mean_case)
other=$(all_rows | awk -F, -v c="$commit" '$1 == "hidden" { for (i = 1; i <= NF; i++) if ($i == "commit") k = i; next }
  k && $k != c { n++ } END { print n + 0 }')
echo "identification_table: ${#units[@]} seeds, $left_cases cases left (levels: $levels); about ${each} s a case with" \
     "-j $jobs on this machine, $((left_cases * each / 60)) minutes in all; this budget ($budget s) reaches about" \
     "$((budget / each)) cases. Rows of another commit than $commit: $other"
if [ "$plan" != 1 ]; then
  start=$SECONDS; ran=0; skipped=0
  for u in "${units[@]}"; do
    IFS=: read -r level seed n <<< "$u"
    left=$((budget - (SECONDS - start))); each=$(mean_case)
    if [ "$left" -lt $((n * each)) ]; then skipped=$((skipped + 1)); continue; fi
    t0=$SECONDS; tmp="$out/.$level.$seed.csv"
    echo "identification_table: $level seed $seed: $n cases (about $((n * each)) s); $left s of the budget left" \
         "(ETA for this seed $(date -d "+$((n * each)) seconds" +%H:%M))"
    # The sweep's own progress (a line a case, unbuffered: its stdout is a file) goes to its log, whose last line is
    # shown when it changes; its cases' rows to a file of their own, appended when all are done.
    log="$out/.$level.$seed.log"; shown=""
    # shellcheck disable=SC2086
    stdbuf -o0 -e0 "$sweep" --hidden "$(cases "$level" "$seed" | tr ' ' ,)" --seeds "$seed" --noise-scale "$(noise "$level")" \
      -j "$jobs" -o "$tmp" ${SWEEP_ARGS:-} > "$log" 2>&1 &
    pid=$!
    while kill -0 "$pid" 2>/dev/null; do
      sleep 5
      line="$(tr '\r' '\n' < "$log" | grep "^hidden sweep [0-9]" | tail -n 1 | cut -c1-140 || true)"
      [ -n "$line" ] && [ "$line" != "$shown" ] && echo "identification_table: $level seed $seed: $line" && shown="$line"
    done
    wait "$pid" || { tail -n 20 "$log"; echo "identification_table: $level seed $seed failed"; exit 1; }
    secs=$(( (SECONDS - t0) / n ))
    if [ ! -f "$out/$level.csv" ]; then head -n 1 "$tmp" | sed 's/$/,commit,seconds/' > "$out/$level.csv"
    elif [ "$(head -n 1 "$tmp"),commit,seconds" != "$(head -n 1 "$out/$level.csv")" ]; then
      echo "identification_table: $out/$level.csv has other columns than this program writes: move it aside"; exit 1
    fi
    # A seed run again (another commit's rows for it were partial) replaces them.
    awk -F, -v s="$seed" 'NR == 1 || $3 != s' "$out/$level.csv" > "$out/.$level.keep" && mv "$out/.$level.keep" "$out/$level.csv"
    tail -n +2 "$tmp" | sed "s/\$/,$commit,$secs/" >> "$out/$level.csv"
    rm -f "$tmp" "$tmp".* "$log"  # the sweep writes its pools beside its rows
    ran=$((ran + n))
    echo "identification_table: $level seed $seed done in $(( (SECONDS - t0) / 60 ))m$(( (SECONDS - t0) % 60 ))s" \
         "($ran cases this run): $(tail -n "$n" "$out/$level.csv" | cut -d, -f1,4 | tr '\n' ' ')"
  done
  [ "$skipped" = 0 ] || echo "identification_table: $skipped seeds not started: the budget left less than their cases' time"
fi
args=()
for level in $levels; do [ -s "$out/$level.csv" ] && args+=(--level "$level=$out/$level.csv"); done
if [ ${#args[@]} -gt 0 ]; then "$py" "$root/tools/sweep_table.py" "${args[@]}"
else echo "identification_table: no case done yet in $out"; fi
