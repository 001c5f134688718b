#!/usr/bin/env python3
"""Plots results/bench/history.jsonl (one record per `hexrefine bench --history` run): for each
benchmark matching PATTERN (a regex; default: the refiners' and the command's largest sizes and
the checker: the brick at 50^3, the refined 50^3 and 75^3 outputs on one and two threads), the median CPU time of every run with its repetitions' range as an error bar, in
run order, labelled by date and commit. Writes results/bench/history.png.

usage: python3 experiments/studies/bench_history/run.py [HISTORY.jsonl] [--pattern REGEX]
       [--out PNG]
"""
import math
import pathlib
import re
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent.parent))
import harness  # noqa: E402
import records as jsonl  # noqa: E402

BENCH = harness.RESULTS / "bench"


def main():
    parser = harness.study_arguments(harness.first_line(__doc__), out=BENCH / "history.png")
    parser.add_argument("history", nargs="?", default=str(BENCH / "history.jsonl"))
    parser.add_argument(
        "--pattern",
        default=r"bench_(full_brick|radial)/(selective|sheet)/50/|bench_command/"
                r"exodus(_2_threads)?/50/|bench_check_brick(_2_threads)?/50/"
                r"|bench_check_refined(_2_threads)?/(50|75)/|bench_real_mesh/")
    args = parser.parse_args()
    records = jsonl.read_records(args.history, "bench_history/run.py")
    if not records:
        harness.fail("bench_history/run.py", f"{args.history}: no records")
    plot(records, args)


def plot(records, args):
    """One panel per benchmark matching args.pattern, written to args.out."""
    pattern = re.compile(args.pattern)
    names = sorted({n for r in records for n in r["benchmarks"] if pattern.search(n)})
    if not names:
        harness.fail("bench_history/run.py", f"no benchmark matches {args.pattern!r}")
    columns = 2
    rows = math.ceil(len(names) / columns)
    fig, axes = plt.subplots(rows, columns, figsize=(11, 2.6 * rows), squeeze=False)
    labels = [f"{r['date'][:10]}\n{r['commit'][:7]}" for r in records]
    for ax, name in zip(axes.flat, names):
        xs, ys, lo, hi = [], [], [], []
        for i, r in enumerate(records):
            b = r["benchmarks"].get(name)
            if not b:
                continue
            xs.append(i)
            ys.append(b["cpu_median"])
            lo.append(b["cpu_median"] - b["cpu_range"][0])
            hi.append(b["cpu_range"][1] - b["cpu_median"])
        ax.errorbar(xs, ys, yerr=[lo, hi], marker="o", capsize=3)
        ax.set_title(name, fontsize=8)
        ax.set_ylabel("CPU s")
        ax.set_ylim(bottom=0)
        ax.set_xticks(range(len(records)))
        ax.set_xticklabels(labels, fontsize=6)
    for ax in list(axes.flat)[len(names):]:
        ax.axis("off")
    fig.suptitle("hexrefine bench history: median CPU time per run, bars = range of repetitions")
    fig.tight_layout()
    harness.savefig_atomic(fig, args.out, 100)
    print(f"wrote {args.out} ({len(names)} benchmarks, {len(records)} runs)")


if __name__ == "__main__":
    main()
