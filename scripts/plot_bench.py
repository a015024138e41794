#!/usr/bin/env python3
"""Plots fdml_bench CSV output: success (paper, strict, top-1) and median time per
localization against the resolution n, one PNG per (scene, m), one colour per method.

usage: plot_bench.py BENCH.csv [BENCH2.csv ...] [--out-dir docs] [--prefix bench] [--summary]
Writes OUT_DIR/PREFIX_<scene>_m<m>.png and prints the paths. With --summary it prints instead
the paper-style Markdown table (success pooled over n, per method and scene x m) of all the
CSV files together. Needs only python3-matplotlib.
"""
import argparse
import csv
import os
import statistics
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

HEADER = ["scene", "m", "n", "method", "trial", "success_paper", "success_strict", "success_top1",
          "candidates", "time_ms", "sparsity_held", "err_pos", "err_theta"]
METRICS = [("success_paper", "paper criterion", "-"), ("success_strict", "strict (5 cm, 2 deg)", "--"),
           ("success_top1", "top-1 strict", ":")]
COLOURS = {"robust": "tab:blue", "robust-k6": "tab:purple", "paper": "tab:orange", "baseline": "tab:green"}


def read_rows(paths):
    rows = []
    for path in paths:
        with open(path, newline="") as f:
            reader = csv.reader(f)
            header = next(reader, None)
            if header is None or header[:len(HEADER)] != HEADER:  # later columns: fov_deg, top_err_*
                sys.exit("%s: unexpected CSV header %s (expected %s)" % (path, header, ",".join(HEADER)))
            for line_no, fields in enumerate(reader, start=2):
                if len(fields) != len(header):
                    sys.exit("%s:%d: expected %d fields, got %d" % (path, line_no, len(header), len(fields)))
                rows.append(dict(zip(header, fields)))
    return rows


def print_summary(rows):
    columns, methods = [], []
    pools = defaultdict(lambda: [0, 0, 0, 0, 0.0, 0.0])  # trials, paper, strict, top1, cand, held
    for r in rows:
        col = (r["scene"], int(r["m"]))
        if col not in columns:
            columns.append(col)
        if r["method"] not in methods:
            methods.append(r["method"])
        p = pools[(r["method"], col)]
        p[0] += 1
        p[1] += int(r["success_paper"])
        p[2] += int(r["success_strict"])
        p[3] += int(r["success_top1"])
        p[4] += int(r["candidates"])
        p[5] += int(r["sparsity_held"])
    print("| method | metric | " + " | ".join("%s m=%d" % c for c in columns) + " |")
    print("|---|---|" + "---:|" * len(columns))
    metrics = [("success %", 1), ("strict %", 2), ("top-1 %", 3), ("candidates", 4), ("sparsity held %", 5)]
    for method in methods:
        for name, i in metrics:
            cells = []
            for c in columns:
                p = pools.get((method, c))
                if not p or p[0] == 0:
                    cells.append("-")
                elif i == 4:
                    cells.append("%.2f" % (p[4] / p[0]))
                else:
                    cells.append("%.1f" % (100.0 * p[i] / p[0]))
            print("| %s | %s | %s |" % (method, name, " | ".join(cells)))


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("csv", nargs="+")
    parser.add_argument("--out-dir", default="docs")
    parser.add_argument("--prefix", default="bench")
    parser.add_argument("--summary", action="store_true", help="print the pooled Markdown table, no plots")
    args = parser.parse_args()
    if args.summary:
        print_summary(read_rows(args.csv))
        return

    # (scene, m) -> method -> n -> list of rows
    cells = defaultdict(lambda: defaultdict(lambda: defaultdict(list)))
    for r in read_rows(args.csv):
        cells[(r["scene"], int(r["m"]))][r["method"]][int(r["n"])].append(r)
    if not cells:
        sys.exit("no rows in %s" % ", ".join(args.csv))
    os.makedirs(args.out_dir, exist_ok=True)
    for (scene, m), methods in sorted(cells.items()):
        fig, (ax_s, ax_t) = plt.subplots(1, 2, figsize=(11, 4.2))
        for method, by_n in sorted(methods.items()):
            ns = sorted(by_n)
            colour = COLOURS.get(method)
            for key, label, style in METRICS:
                rates = [100.0 * sum(int(r[key]) for r in by_n[n]) / len(by_n[n]) for n in ns]
                ax_s.plot(ns, rates, style, marker="o", color=colour, label="%s, %s" % (method, label))
            times = [statistics.median(float(r["time_ms"]) for r in by_n[n]) for n in ns]
            ax_t.plot(ns, times, "-", marker="o", color=colour, label=method)
        trials = max(len(v) for by_n in methods.values() for v in by_n.values())
        ax_s.set_title("%s, m = %d: success (%d trials per point)" % (scene, m, trials))
        ax_s.set_xlabel("resolution n")
        ax_s.set_ylabel("success [%]")
        ax_s.set_ylim(-2, 102)
        ax_s.grid(True, alpha=0.3)
        ax_s.legend(fontsize=7, loc="lower right")
        ax_t.set_title("median time per localization")
        ax_t.set_xlabel("resolution n")
        ax_t.set_ylabel("time [ms]")
        ax_t.set_yscale("log")
        ax_t.grid(True, which="both", alpha=0.3)
        ax_t.legend(fontsize=8)
        fig.tight_layout()
        out = os.path.join(args.out_dir, "%s_%s_m%d.png" % (args.prefix, scene, m))
        fig.savefig(out, dpi=90)
        plt.close(fig)
        print(out)


if __name__ == "__main__":
    main()
