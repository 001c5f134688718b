#!/usr/bin/env python3
"""Markdown tables of results/sheet.json (the Google Benchmark output of bench_refiners).

Usage: python3 experiments/studies/sheet_benchmark/run.py [results/sheet.json]
Prints one row per benchmark case and refiner (medians over the repetitions) and the time ratio
sheet / selective where both refiners ran.
"""
import json
import pathlib
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent.parent))
import harness  # noqa: E402


def load(path):
    with open(path) as f:
        data = json.load(f)
    rows, errors = {}, {}
    for b in data["benchmarks"]:
        name = b.get("run_name", b["name"])
        if b.get("error_occurred"):
            errors[name] = b.get("error_message", "")
            continue
        if b.get("run_type") == "aggregate" and b.get("aggregate_name") != "median":
            continue
        if b.get("run_type") == "iteration" and any(
                x.get("run_name") == name and x.get("run_type") == "aggregate"
                for x in data["benchmarks"]):
            continue
        rows[name] = b
    return data, rows, errors


def case_and_method(name):
    parts = name.split("/")
    case, method = parts[0], parts[1]
    arg = parts[2] if len(parts) > 2 and parts[2].isdigit() else ""
    return (case + ("/" + arg if arg else "")), method


def main():
    parser = harness.study_arguments(harness.first_line(__doc__), out=None)
    parser.add_argument("benchmarks", nargs="?", default=str(harness.RESULTS / "sheet.json"),
                        help="bench_refiners' JSON output (default %(default)s)")
    data, rows, errors = load(parser.parse_args().benchmarks)
    ctx = data["context"]
    print(f"Machine: {ctx.get('num_cpus')} CPUs at {ctx.get('mhz_per_cpu')} MHz, "
          f"load average {ctx.get('load_avg')}, build {ctx.get('library_build_type')} "
          f"(benchmark library), date {ctx.get('date')}.\n")
    print("| case | refiner | initial | targets | added | final | created | deleted | "
          "sheet passes | wall ms | CPU ms | CPU us / initial hex |")
    print("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    by_case = {}
    order = {"sheet": 0, "sheet_one_per_pass": 1, "selective": 2}

    def key(item):
        case, method = case_and_method(item[0])
        base, _, arg = case.partition("/")
        return (base, int(arg) if arg else 0, order.get(method, 9))

    for name, b in sorted(rows.items(), key=key):
        case, method = case_and_method(name)
        by_case.setdefault(case, {})[method] = b
        init = b["initial_hexes"]
        print(f"| {case} | {method} | {init:.0f} | {b['targets']:.0f} | "
              f"{b['added_targets']:.0f} | {b['final_hexes']:.0f} | {b['hexes_created']:.0f} | "
              f"{b['hexes_deleted']:.0f} | {b['sheet_passes']:.0f} | {b['real_time']:.1f} | "
              f"{b['cpu_time']:.1f} | {1000 * b['cpu_time'] / init:.2f} |")
    for name, msg in errors.items():
        case, method = case_and_method(name)
        if method in by_case.get(case, {}):
            continue
        print(f"| {case} | {method} | skipped: {msg} |||||||||")
    print()
    ratios = [(c, m["sheet"], m["selective"]) for c, m in by_case.items()
              if "sheet" in m and "selective" in m]
    if ratios:
        print("| case | sheet / selective (wall) | sheet / selective (CPU) | final hexes "
              "sheet / selective |")
        print("|---|---:|---:|---:|")
        def case_key(case):
            base, _, arg = case.partition("/")
            return (base, int(arg) if arg else 0)

        for c, s, p in sorted(ratios, key=lambda r: case_key(r[0])):
            print(f"| {c} | {s['real_time'] / p['real_time']:.2f} | "
                  f"{s['cpu_time'] / p['cpu_time']:.2f} | "
                  f"{s['final_hexes']:.0f} / {p['final_hexes']:.0f} |")


if __name__ == "__main__":
    main()
