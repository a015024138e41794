#!/usr/bin/env bash
# Takes docs/rviz_demo.png: the simulation with rviz under a virtual display, after a kidnap
# and a relocalization. Run as: xvfb-run -a -s "-screen 0 1280x800x24" bash scripts/screenshot.sh
set -euo pipefail
source "$(dirname "$0")/common.sh"
source_workspace
start_simulation "${FDML_DEMO_PORT:-11392}" "$WS/screenshot_launch.log" rviz:=true
/usr/bin/python3 "$REPO_DIR/scripts/demo_client.py" --kidnaps 6 --stop-when-unambiguous
sleep 3  # let rviz draw the last answer before the picture
import -window root "$REPO_DIR/docs/rviz_demo.png"
echo "wrote $REPO_DIR/docs/rviz_demo.png"
