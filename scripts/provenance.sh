# Sourced by the scripts whose rows the results page reads (docs/results.md): provenance_fields ROOT prints
# "date,commit,machine" for a CSV row: the UTC date, the repository's short commit (with + where host/, kernels/ or
# perf/ differ from it) and the CPU's model name, commas taken out.
provenance_fields() {
  local commit machine
  commit="$(git -C "$1" rev-parse --short HEAD 2>/dev/null || echo unknown)"
  git -C "$1" diff --quiet HEAD -- host kernels perf 2>/dev/null || commit="$commit+"
  machine="$(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo 2>/dev/null | head -1 | tr -d ',')"
  echo "$(date -u +%Y-%m-%d),$commit,${machine:-unknown}"
}
