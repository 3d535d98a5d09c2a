#!/usr/bin/env bash
# The test command (README, .ci/run): installs and builds everything, runs the suite, checks that no test dropped
# out, then runs the gates (tests/run_gates.sh: the fast tests under ASan and UBSan, and each fuzz harness for a
# fixed time). docs/testing.md says what each layer checks.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
bash scripts/setup.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j2
echo "test: set-up and build in ${SECONDS} s"
log="$(mktemp)"
trap 'rm -f "$log"' EXIT
# Tests declare the cores they keep busy (PROCESSORS, tests/CMakeLists.txt), so ctest fills every core without
# putting a test beside others on cores it needs. The long cases: ctest -L long.
(cd build && ctest -j"$(nproc)" --output-on-failure -LE long) | tee "$log"
# ctest's summary: "100% tests passed, 0 tests failed out of N"; skipped tests are listed as "Not Run" / "Skipped".
total=$(sed -n 's/.*tests failed out of \([0-9]*\).*/\1/p' "$log" | tail -1)
skipped=$(grep -c '\*\*\*Skipped\|Not Run' "$log" || true)
passed=$((total - skipped))
expected=$(grep -v '^#' tests/expected_test_count | head -1)
echo "test count: ${passed} passed (${skipped} skipped of ${total}); at least ${expected} expected (tests/expected_test_count)"
if [ "$passed" -lt "$expected" ]; then
  echo "test count: FAILED: fewer tests passed than tests/expected_test_count says; a test file or case dropped out" >&2
  exit 1
fi
echo "test: the suite done at ${SECONDS} s"
bash tests/run_gates.sh
echo "test: the gates done at ${SECONDS} s"
