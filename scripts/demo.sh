#!/usr/bin/env bash
# The package's main job, headless: an interim core demo until the simulator and node land.
set -euo pipefail
source "$(dirname "$0")/common.sh"
"$WS/devel/lib/fdml_localization/fdml_demo_core" "$REPO_DIR/maps/office.poly" 7
