#!/usr/bin/env bash
# make test-asan: builds the core and ROS unit tests (gtests without a roscore) and the fuzz
# suite with -fsanitize=address,undefined in a separate workspace (ws-asan/, git-ignored), runs
# them, and ends with "N passed, N failed". Any sanitizer report fails the run.
set -uo pipefail
export WS="${WS_ASAN:-$(cd "$(dirname "$0")/.." && pwd)/ws-asan}"
source "$(dirname "$0")/common.sh"
# ASAN_TARGETS="test_core_map test_fuzz" narrows the run (e.g. to what a change touched).
read -r -a TARGETS <<<"${ASAN_TARGETS:-test_core_geometry test_core_util test_core_map test_core_localization test_core_voxel test_core_tracking test_simulation test_tools test_ros_units test_fuzz}"

if ! catkin_build -DFDML_SANITIZE=ON "${TARGETS[@]}"; then
  echo "asan build failed"
  echo "0 passed, 1 failed"
  exit 1
fi
# halt_on_error: the first report fails the binary; leaks are reported at exit.
export ASAN_OPTIONS="halt_on_error=1:detect_leaks=1:abort_on_error=0:exitcode=86"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1:exitcode=87"
export OMP_NUM_THREADS="${OMP_NUM_THREADS:-2}"
# The ROS unit tests resolve package:// URIs through ROS_PACKAGE_PATH: the workspace's own.
source_workspace
passed=0
failed=0
for target in "${TARGETS[@]}"; do
  binary="$(find "$WS/devel" "$WS/build" -name "$target" -type f -perm -u+x 2>/dev/null | head -n 1)"
  if [ -z "$binary" ]; then
    echo "[asan] $target: binary not found"
    failed=$((failed + 1))
    continue
  fi
  log="$WS/asan_$target.log"
  if (cd "$REPO_DIR" && "$binary" >"$log" 2>&1); then
    echo "[asan] $target: passed ($(grep -c '^\[       OK \]' "$log") tests)"
    passed=$((passed + 1))
  else
    echo "[asan] $target: FAILED (log: $log)"
    grep -E "ERROR: AddressSanitizer|runtime error:|ERROR: LeakSanitizer|\[  FAILED  \]" "$log" | head -n 20
    failed=$((failed + 1))
  fi
done
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
