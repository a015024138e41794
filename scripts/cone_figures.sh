#!/usr/bin/env bash
# The figures of issue 18 (cone sensors): fdml_bench's protocol with every reading a cone of
# 0 (rays), 2, 15, 27 and 30 degrees, turning in place and driving (--translate), without and
# with 10 disc obstacles; one Markdown table of success, candidates and time against rays.
#   TRIALS=10 RESOLUTION=100 ENGINE=voxel MAPS="apartment office" FOVS="0 2 15 27 30" \
#   KPRIME=6 MOTIONS="turn drive" OUT=ws/cone_figures bash scripts/cone_figures.sh
# KPRIME: fdml_bench --min-inliers, 6 (the paper's fixed k', the default) or auto (maximum
# consensus, as the node and fdml_localize run).
# Columns: top1% = best-ranked candidate within 5 cm and 2 deg; best10% = best-ranked candidate
# within 10 cm and 5 deg (issue 18's criterion); near% = nearest candidate within 10 cm and 5 deg
# (the truth among the candidates); strict% = any candidate within 5 cm and 2 deg;
# cand = mean candidates; med_ms = median localization time; x_rays = med_ms / the rays' med_ms.
set -euo pipefail
source "$(dirname "$0")/common.sh"
bench="$WS/devel/lib/fdml_localization/fdml_bench"
TRIALS="${TRIALS:-10}"
RESOLUTION="${RESOLUTION:-100}"
ENGINE="${ENGINE:-voxel}"
MAPS="${MAPS:-apartment}"
FOVS="${FOVS:-0 2 15 27 30}"
KPRIME="${KPRIME:-6}"
MOTIONS="${MOTIONS:-turn drive}"
OUT="${OUT:-$WS/cone_figures_k$KPRIME}"
[ -x "$bench" ] || { echo "cone_figures: build fdml_bench first (make build)" >&2; exit 2; }
mkdir -p "$OUT"
map_args=()
for m in $MAPS; do map_args+=(--map "$REPO_DIR/maps/$m.poly"); done
echo "cone_figures: $(date -u '+%Y-%m-%d %H:%M UTC'), load: $(uptime | sed 's/.*load average: //'), k' $KPRIME" >&2
for motion in $MOTIONS; do
  extra=()
  [ "$motion" = drive ] && extra=(--translate)
  for fov in $FOVS; do
    csv="$OUT/${motion}_fov${fov}.csv"
    echo "== $motion, fov $fov deg -> $csv" >&2
    "$bench" "${map_args[@]}" --obstacles 0,10 --resolution "$RESOLUTION" --trials "$TRIALS" \
      --engine "$ENGINE" --min-inliers "$KPRIME" --fov "$fov" "${extra[@]}" --csv "$csv" >/dev/null
  done
done
# shellcheck disable=SC2086  # FOVS is a list
python3 - "$OUT" "$KPRIME" "$MOTIONS" $FOVS <<'PY' | tee "$OUT/cone_figures.md"
import csv, math, statistics, sys
out, kprime, motions, fovs = sys.argv[1], sys.argv[2], sys.argv[3].split(), sys.argv[4:]
print("| scene | motion | m | fov deg | k' | trials | top1% | best10% | near% | strict% | cand | med_ms | x_rays |")
print("|---|---|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|")
within = lambda pos, theta: pos != "" and float(pos) <= 0.10 and float(theta) <= math.radians(5.0)
for motion in motions:
    cells, ray_ms = {}, {}
    for fov in fovs:
        for r in csv.DictReader(open(f"{out}/{motion}_fov{fov}.csv")):
            cells.setdefault((r["scene"], int(r["m"]), fov), []).append(r)
    for (scene, m, fov), rows in sorted(cells.items(), key=lambda kv: (kv[0][0], kv[0][1], float(kv[0][2]))):
        n = len(rows)
        pct = lambda k: 100.0 * sum(int(r[k]) for r in rows) / n
        near = 100.0 * sum(1 for r in rows if within(r["err_pos"], r["err_theta"])) / n
        best10 = 100.0 * sum(1 for r in rows if within(r["top_err_pos"], r["top_err_theta"])) / n
        ms = statistics.median(float(r["time_ms"]) for r in rows)
        if float(fov) == 0.0:
            ray_ms[(scene, m)] = ms
        ratio = ms / ray_ms[(scene, m)] if ray_ms.get((scene, m)) else float("nan")
        cand = statistics.mean(int(r["candidates"]) for r in rows)
        print(f"| {scene} | {motion} | {m} | {fov} | {kprime} | {n} | {pct('success_top1'):.0f} | {best10:.0f} | {near:.0f} | "
              f"{pct('success_strict'):.0f} | {cand:.1f} | {ms:.0f} | {ratio:.2f} |")
PY
echo "cone_figures: table in $OUT/cone_figures.md" >&2
