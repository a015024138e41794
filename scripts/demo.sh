#!/usr/bin/env bash
# The package's main job: a simulated kidnapped-robot relocalization.
# Launches fdml_simulator + fdml_localizer (launch/simulation.launch, scenario config/scenarios/demo.yaml)
# with its own ROS master on a private port, kidnaps the robot KIDNAPS times, calls ~relocalize
# after each and prints truth, best candidate, error, candidates and solve time, then a summary.
#   RVIZ=1      also open rviz (needs a display; under no display use: xvfb-run -a make demo RVIZ=1)
#   KIDNAPS=N   number of kidnaps (default 5)
#   SCENARIO=.. MAP=..   another scenario in config/scenarios/ and the map it uses
set -euo pipefail
source "$(dirname "$0")/common.sh"
source_workspace

RVIZ="${RVIZ:-0}"
KIDNAPS="${KIDNAPS:-5}"
SCENARIO="${SCENARIO:-demo}"
MAP="${MAP:-apartment}"

rviz_arg=false
if [ "$RVIZ" = "1" ]; then
  if [ -z "${DISPLAY:-}" ]; then
    echo "demo: RVIZ=1 needs a display; run 'xvfb-run -a make demo RVIZ=1' for a virtual one" >&2
    exit 2
  fi
  rviz_arg=true
fi

log="$WS/demo_launch.log"
echo "demo: launching the simulation (scenario $SCENARIO, map $MAP, rviz $rviz_arg); log: $log"
start_simulation "${FDML_DEMO_PORT:-11391}" "$log" rviz:="$rviz_arg" scenario:="$SCENARIO" map:="$MAP" || exit 2

status=0
/usr/bin/python3 "$REPO_DIR/scripts/demo_client.py" --kidnaps "$KIDNAPS" || status=$?
if [ "$status" -eq 2 ]; then
  echo "demo: the nodes did not come up; the end of $log:" >&2
  tail -n 30 "$log" >&2
fi
if [ "$rviz_arg" = true ] && [ "$status" -ne 2 ] && [ -t 0 ]; then
  read -r -p "demo: rviz stays open; press Enter to quit. " _ || true
fi
exit "$status"
