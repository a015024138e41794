#!/usr/bin/env bash
# The figures of issue 18 (cone sensors): fdml_bench's protocol with every reading a cone of
# 0 (rays), 2, 15, 27 and 30 degrees, turning in place and driving (--translate), without and
# with 10 disc obstacles; one Markdown table of success, candidates and time against rays.
#   TRIALS=10 RESOLUTION=100 ENGINE=voxel MAPS="apartment office" FOVS="0 2 15 27 30" \
#   OUT=ws/cone_figures bash scripts/cone_figures.sh
# Columns: top1% = best-ranked candidate within 5 cm and 2 deg; near% = nearest candidate within
# 10 cm and 5 deg (issue 18's criterion); strict% = any candidate within 5 cm and 2 deg;
# cand = mean candidates; med_ms = median localization time; x_rays = med_ms / the rays' med_ms.
set -euo pipefail
source "$(dirname "$0")/common.sh"
bench="$WS/devel/lib/fdml_localization/fdml_bench"
TRIALS="${TRIALS:-10}"
RESOLUTION="${RESOLUTION:-100}"
ENGINE="${ENGINE:-voxel}"
MAPS="${MAPS:-apartment}"
FOVS="${FOVS:-0 2 15 27 30}"
OUT="${OUT:-$WS/cone_figures}"
[ -x "$bench" ] || { echo "cone_figures: build fdml_bench first (make build)" >&2; exit 2; }
mkdir -p "$OUT"
map_args=()
for m in $MAPS; do map_args+=(--map "$REPO_DIR/maps/$m.poly"); done
echo "cone_figures: $(date -u '+%Y-%m-%d %H:%M UTC'), load: $(uptime | sed 's/.*load average: //')" >&2
for motion in turn drive; do
  extra=()
  [ "$motion" = drive ] && extra=(--translate)
  for fov in $FOVS; do
    csv="$OUT/${motion}_fov${fov}.csv"
    echo "== $motion, fov $fov deg -> $csv" >&2
    "$bench" "${map_args[@]}" --obstacles 0,10 --resolution "$RESOLUTION" --trials "$TRIALS" \
      --engine "$ENGINE" --fov "$fov" "${extra[@]}" --csv "$csv" >/dev/null
  done
done
# shellcheck disable=SC2086  # FOVS is a list
python3 - "$OUT" $FOVS <<'PY' | tee "$OUT/cone_figures.md"
import csv, math, statistics, sys
out, fovs = sys.argv[1], sys.argv[2:]
print("| scene | motion | m | fov deg | trials | top1% | near% | strict% | cand | med_ms | x_rays |")
print("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
for motion in ("turn", "drive"):
    cells, ray_ms = {}, {}
    for fov in fovs:
        for r in csv.DictReader(open(f"{out}/{motion}_fov{fov}.csv")):
            cells.setdefault((r["scene"], int(r["m"]), fov), []).append(r)
    for (scene, m, fov), rows in sorted(cells.items(), key=lambda kv: (kv[0][0], kv[0][1], float(kv[0][2]))):
        n = len(rows)
        pct = lambda k: 100.0 * sum(int(r[k]) for r in rows) / n
        near = 100.0 * sum(1 for r in rows if r["err_pos"] and float(r["err_pos"]) <= 0.10
                           and float(r["err_theta"]) <= math.radians(5.0)) / n
        ms = statistics.median(float(r["time_ms"]) for r in rows)
        if float(fov) == 0.0:
            ray_ms[(scene, m)] = ms
        ratio = ms / ray_ms[(scene, m)] if ray_ms.get((scene, m)) else float("nan")
        cand = statistics.mean(int(r["candidates"]) for r in rows)
        print(f"| {scene} | {motion} | {m} | {fov} | {n} | {pct('success_top1'):.0f} | {near:.0f} | "
              f"{pct('success_strict'):.0f} | {cand:.1f} | {ms:.0f} | {ratio:.2f} |")
PY
echo "cone_figures: table in $OUT/cone_figures.md" >&2
