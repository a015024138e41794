#!/usr/bin/env bash
# make bench: the Google Benchmark suite (ray casting, localizer stages, engines) and a short
# fdml_bench run of the paper's protocol on this package's own maps. Figures, with the full
# commands used for the record, are in docs/BENCHMARKS.md.
#   PAPER_MAPS=/path/to/shared/maps/paper   also run the paper's scenes (never copied here)
set -euo pipefail
source "$(dirname "$0")/common.sh"
bin="$WS/devel/lib/fdml_localization"
out="$WS/bench"
mkdir -p "$out"
echo "== Google Benchmark (nproc $(nproc), $(date -u +%Y-%m-%dT%H:%MZ))"
OMP_WAIT_POLICY=passive "$bin/fdml_benchmarks" --benchmark_counters_tabular=true \
  --benchmark_out="$out/benchmarks.json" --benchmark_out_format=json
echo "== fdml_bench on maps/ (5 trials per cell)"
"$bin/fdml_bench" --map "$REPO_DIR/maps/l_room.poly" --map "$REPO_DIR/maps/office.poly" \
  --obstacles 10 --resolution 100 --trials 5 --method robust --csv "$out/own_maps.csv"
if [ -n "${PAPER_MAPS:-}" ]; then
  echo "== fdml_bench on the paper's scenes (5 trials per cell)"
  "$bin/fdml_bench" --map "$PAPER_MAPS/lab_lidar.poly" --map "$PAPER_MAPS/checkpoint.poly:0.25" \
    --random 70:2 --obstacles 10,30 --resolution 100 --trials 5 --csv "$out/paper_maps.csv"
fi
echo "results in $out"
