#!/usr/bin/env bash
# make fuzz: the fuzz suite (test/fuzz) at full size. FUZZ_CASES (default 100000) cases are
# shared out among the generators; the fixed seeds make every run the same. Ends with the
# suite's summary (cases, time, failures).
set -uo pipefail
source "$(dirname "$0")/common.sh"
if ! catkin_build test_fuzz; then
  echo "build failed"
  exit 1
fi
binary="$(find "$WS/devel" "$WS/build" -name test_fuzz -type f -perm -u+x 2>/dev/null | head -n 1)"
cd "$REPO_DIR" && FDML_FUZZ_CASES="${FUZZ_CASES:-100000}" "$binary"
