#!/usr/bin/env bash
# Builds, runs every gtest and rostest target, and ends with "N passed, N failed".
# Exits non-zero on any failure, on a build failure, or when no test ran.
set -uo pipefail
source "$(dirname "$0")/common.sh"

if ! catkin_build; then
  echo "build failed"
  echo "0 passed, 1 failed"
  exit 1
fi
results="$WS/build/test_results/fdml_localization"
rm -rf "$results"
(cd "$WS" && catkin_make -j"$JOBS" -DPYTHON_EXECUTABLE=/usr/bin/python3 run_tests) 2>&1 \
  | tee "$WS/run_tests.log" | grep -E "^\[ *(RUN|OK|FAILED|PASSED|  FAILED) *\]|^\[ROSTEST\]|^ *\[.*\]\[(passed|FAILURE|ERROR)\]|rostest|Error" || true
/usr/bin/python3 "$(dirname "$0")/summarize_results.py" "$results"
