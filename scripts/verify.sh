#!/usr/bin/env bash
# make verify: builds verify_localization and runs the whole verification suite (issue 16):
# random trials over reading geometries on small maps, both engines, noise-free and noisy,
# checked against the truth and a sampled reference; prints the figures (docs/BENCHMARKS.md).
#   VERIFY_TRIALS=N VERIFY_MINUTES=M   override the default 10,000 trials or 15 minutes
#   VERIFY_MAPS="a.poly b.poly:0.25"   verify on these polygon maps (each scaled by :SCALE) ...
#   VERIFY_RANDOM_MAPS=N VERIFY_BUILDINGS=N VERIFY_ROOMS=N   ... and on N random 70-gons, N
#                                      generated 12 x 9 m buildings, N furnished rooms (rotated
#                                      boxes, round pillars, round halls) drawn from the seed,
#                                      instead of the small ones
#   VERIFY_SCALE=S                     the generated maps scaled by S (0.05 to 20) about the origin
#   VERIFY_SEED=S                      the trials' seed (default 16)
#   VERIFY_RESOLUTION=N                the engines' resolution (default 64)
#   VERIFY_K=MIN:MAX                   readings per trial (default 4:30; 4:6 hunts where few
#                                      readings leave thousands of leaves tied)
#   VERIFY_FOV=DEG                     every reading a cone of that full field of view (0 to 180)
set -euo pipefail
source "$(dirname "$0")/common.sh"
catkin_build verify_localization
cd "$REPO_DIR"
echo "== verify_localization ($(nproc) cores, $(date -u +%Y-%m-%dT%H:%MZ), load: $(cut -d' ' -f1-3 /proc/loadavg))"
map_args=()
for map in ${VERIFY_MAPS:-}; do
  map_args+=(--map "$map")
done
[ -z "${VERIFY_RANDOM_MAPS:-}" ] || map_args+=(--random-maps "$VERIFY_RANDOM_MAPS")
[ -z "${VERIFY_BUILDINGS:-}" ] || map_args+=(--buildings "$VERIFY_BUILDINGS")
[ -z "${VERIFY_ROOMS:-}" ] || map_args+=(--rooms "$VERIFY_ROOMS")
[ -z "${VERIFY_SCALE:-}" ] || map_args+=(--scale "$VERIFY_SCALE")
[ -z "${VERIFY_K:-}" ] || map_args+=(--k "$VERIFY_K")
[ -z "${VERIFY_FOV:-}" ] || map_args+=(--fov "$VERIFY_FOV")
"$WS/devel/lib/fdml_localization/verify_localization" --trials "${VERIFY_TRIALS:-10000}" \
  --minutes "${VERIFY_MINUTES:-15}" --resolution "${VERIFY_RESOLUTION:-64}" --seed "${VERIFY_SEED:-16}" \
  "${map_args[@]}"
