#!/usr/bin/env bash
# Tracking in the 60 x 40 m building (issue 17): test/rostest/tracking_building.test, the
# building_drive scenario at real time (about 100 s of wall time, so not part of make test).
# Prints the scorer's summary (right / wrong / absent, first fix) and the localizer's global
# searches; figures in docs/BENCHMARKS.md (Tracking). Build first:
#   bash -c 'source scripts/common.sh; catkin_build fdml_localizer fdml_simulator test_tracking_patrol'
#   DURATION=120 scripts/tracking_building.sh   (simulated seconds of driving; default 90)
set -euo pipefail
source "$(dirname "$0")/common.sh"
source_workspace
log="$(mktemp)"
status=0
rostest fdml_localization tracking_building.test duration:="${DURATION:-90.0}" >"$log" 2>&1 || status=$?
grep -h "fdml_localizer: global search\|kidnap detected\|tracking patrol:" "$log" "$ROS_LOG_DIR"/latest/*stdout.log \
  2>/dev/null | sed 's/.*\]: //' || true
summary="$(grep -rl "tracking patrol:" "$ROS_LOG_DIR" 2>/dev/null | xargs -r ls -t | head -1)"
[ -n "$summary" ] && grep -h "tracking patrol:\|wrong at" "$summary" | sed 's/.*\]: //'
grep -h "RESULT" "$log" || true
rm -f "$log"
exit "$status"
