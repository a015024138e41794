#!/usr/bin/env bash
# Range soak of fdml_localizer (issue 15; not part of make test): a master of its own, the node on
# the test room, and fdml_soak_client (test/soak/soak_client.cpp) sending Range at RATE Hz for DURATION s with a new
# frame id every 10th message (frames never on tf: every reading waits ~transform_tolerance and
# is dropped, the worst case for the queue and the per-frame state). Prints VmRSS and the node's
# diagnostics every 30 s; exits non-zero when memory or the queue grew without bound.
#   scripts/soak.sh [DURATION_S=600] [RATE_HZ=1000]
set -euo pipefail
source "$(dirname "$0")/common.sh"
duration="${1:-600}"
rate="${2:-1000}"
port="${SOAK_PORT:-11391}"
log_dir="$WS/soak"
mkdir -p "$log_dir"
source_workspace
export ROS_MASTER_URI="http://localhost:$port"
export ROS_IP=127.0.0.1

roscore -p "$port" >"$log_dir/roscore.log" 2>&1 &
core_pid=$!
node_pid=""
cleanup() {
  [ -n "$node_pid" ] && kill -INT "$node_pid" 2>/dev/null && wait "$node_pid" 2>/dev/null
  kill -INT "$core_pid" 2>/dev/null && wait "$core_pid" 2>/dev/null
  return 0
}
trap cleanup EXIT
for _ in $(seq 300); do
  rosparam list >/dev/null 2>&1 && break
  sleep 0.1
done

"$WS/devel/lib/fdml_localization/fdml_localizer" __name:=fdml_localizer \
  _map_file:="$REPO_DIR/test/data/node_test_room.poly" _resolution:=64 _cache_dir:="" _threads:=1 \
  >"$log_dir/fdml_localizer.log" 2>&1 &
node_pid=$!
echo "soak: ${duration} s at ${rate} Hz against fdml_localizer (pid $node_pid), logs in $log_dir"
"$WS/devel/lib/fdml_localization/fdml_soak_client" "$node_pid" "$duration" "$rate" \
  "$(( duration < 300 ? 10 : 30 ))"
