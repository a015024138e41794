#!/usr/bin/env bash
# make verify: builds verify_localization and runs the whole verification suite (issue 16):
# random trials over reading geometries on small maps, both engines, noise-free and noisy,
# checked against the truth and a sampled reference; prints the figures (docs/BENCHMARKS.md).
#   VERIFY_TRIALS=N VERIFY_MINUTES=M   override the default 10,000 trials or 15 minutes
set -euo pipefail
source "$(dirname "$0")/common.sh"
catkin_build verify_localization
cd "$REPO_DIR"
echo "== verify_localization ($(nproc) cores, $(date -u +%Y-%m-%dT%H:%MZ), load: $(cut -d' ' -f1-3 /proc/loadavg))"
"$WS/devel/lib/fdml_localization/verify_localization" --trials "${VERIFY_TRIALS:-10000}" \
  --minutes "${VERIFY_MINUTES:-15}"
