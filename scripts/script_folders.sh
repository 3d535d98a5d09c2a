# Sourced by the scripts in perf/ and tests/ (not run on its own): the build folder a script is told to use, checked
# with a message that says how to name another, and the scratch folders a script clears, cleared only where that
# script made them (issue 87: a WORK named by mistake lost a user's files).

# build_folder SCRIPT: $BUILD (default: the repository's build/) as an absolute path; a missing folder ends the script
# with a message naming BUILD=.
build_folder() {
  local b="${BUILD:-$root/build}"
  [ -d "$b" ] || { echo "$1: BUILD=$b: no such folder (build triaxdem there first, or name its build folder with BUILD=)" >&2; exit 2; }
  realpath "$b"
}

# fresh_folder SCRIPT DIR: DIR emptied and made again, with a marker file of its own. A DIR that holds files and no
# marker is refused, and nothing in it is removed: it may be a user's folder.
fresh_folder() {
  local d="$2"
  if [ -e "$d" ] && [ -n "$(ls -A "$d" 2>/dev/null)" ] && [ ! -f "$d/.triaxdem_scratch" ]; then
    echo "$1: $d holds files this script did not make: name a new or empty folder (nothing was removed)" >&2
    exit 2
  fi
  rm -rf "$d"
  mkdir -p "$d"
  touch "$d/.triaxdem_scratch"
}
