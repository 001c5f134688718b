#!/usr/bin/env python3
"""Measures the issue-32 targets: the checker at >= 10 M hexes/s with two threads on the outputs
of full refinements of 50^3 and 75^3 bricks, and the whole `hexrefine refine` command at most
3 x its refine stage (binary VTU and Exodus II), each a median of RUNS runs with the spread.

For each size n (brick n^3, all hexes refined by the Selective Approach, trilinear placement:
27 n^3 output hexes):
- bench_checker (Google Benchmark, RUNS repetitions): mesh_check of the output in memory,
  without a reference (what `hexrefine check` runs) and with the brick as the reference (what
  `hexrefine refine` runs), one and two threads; real and process CPU time; hexes/s =
  output hexes / median real time.
- `hexrefine check OUT.vtu --threads T` (T = 1, 2), RUNS runs: the command's check stage (wall
  and CPU seconds from its report) and its read stage.
- `hexrefine refine BRICK.e OUT.{vtu,e} --threads 2`, RUNS runs: the command's wall time (this
  script's clock around the process) against its refine stage (from its report), and its other
  stages; every run starts without its output file.
The machine's load average before and after, the date, the commit and the CPU model go into
the JSON. Writes results/performance/checker.json and results/performance/checker.md (the
section of results/performance.md). Needs a Release build with HEXREFINE_BENCHMARKS=ON
(hexrefine and bench_checker, found beside --hexrefine), about 4 GB of memory and 3 GB of disk in $TMPDIR; about ten
minutes on an idle two-core machine.

    python3 experiments/studies/checker/run.py [--runs 5] [--sizes 50 75]
        [--out results/performance] [--hexrefine build/experiments/hexrefine]
"""

import json
import os
import pathlib
import statistics
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent.parent))
import harness  # noqa: E402


def load_average():
    return [float(x) for x in open("/proc/loadavg").read().split()[:3]]


def run(cmd, **kwargs):
    start = time.perf_counter()
    subprocess.run([str(c) for c in cmd], check=True, stdout=subprocess.DEVNULL, **kwargs)
    return time.perf_counter() - start


def spread(values):
    values = sorted(values)
    return {"median": statistics.median(values), "min": values[0], "max": values[-1],
            "runs": values}


def bench_checker(build, size, runs):
    out = subprocess.run(
        [str(build / "bench_checker"), f"--benchmark_filter=/{size}/",
         f"--benchmark_repetitions={runs}", "--benchmark_report_aggregates_only=false",
         "--benchmark_format=json"], check=True, capture_output=True, text=True).stdout
    data = json.loads(out)
    results = {}
    for b in data["benchmarks"]:
        if b.get("run_type") != "iteration":
            continue
        name = b["run_name"].split("/")[0]
        entry = results.setdefault(name, {"real_s": [], "cpu_s": [], "hexes": b["hexes"]})
        scale = {"ms": 1e-3, "us": 1e-6, "ns": 1e-9, "s": 1.0}[b["time_unit"]]
        entry["real_s"].append(b["real_time"] * scale)
        entry["cpu_s"].append(b["cpu_time"] * scale)
    for name, entry in results.items():
        entry["real_s"] = spread(entry["real_s"])
        entry["cpu_s"] = spread(entry["cpu_s"])
        entry["hexes_per_s"] = entry["hexes"] / entry["real_s"]["median"]
        entry["hexes_per_cpu_s"] = entry["hexes"] / entry["cpu_s"]["median"]
    return {"huge_pages": data["context"].get("huge_pages"), "benchmarks": results}


def main():
    parser = harness.study_arguments(harness.first_line(__doc__),
                                     out=harness.RESULTS / "performance", hexrefine=True)
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--sizes", type=int, nargs="+", default=[50, 75])
    args = parser.parse_args()
    hexrefine = pathlib.Path(args.hexrefine)
    build = hexrefine.parent
    cpu = next((line.split(":", 1)[1].strip() for line in open("/proc/cpuinfo")
                if line.startswith("model name")), "")
    versions = set()
    record = dict(harness.provenance(hexrefine), cpu=cpu, cores=os.cpu_count(), runs=args.runs,
                  load_average_before=load_average(), sizes={})
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        for n in args.sizes:
            size = {"hexes_in": n ** 3, "hexes_out": 27 * n ** 3}
            brick = tmp / f"b{n}.e"
            run([hexrefine, "generate", "brick", brick, "--dims", f"{n},{n},{n}"])
            size["bench_checker"] = bench_checker(build, n, args.runs)
            # The outputs `check` reads: binary VTU (the default) and Exodus II.
            for ext in ["vtu", "e"]:
                out = tmp / f"o{n}.{ext}"
                run([hexrefine, "refine", brick, out, "--select", "all", "--method", "selective",
                     "--placement", "trilinear", "--threads", "2"])
            checks = {}
            for threads in [1, 2]:
                stages = {"check_s": [], "check_cpu_s": [], "read_s": [], "wall_s": []}
                for _ in range(args.runs):
                    report = tmp / "check.json"
                    wall = run([hexrefine, "check", tmp / f"o{n}.vtu", "--threads", threads,
                                "--report", report])
                    r = json.loads(report.read_text())
                    stages["check_s"].append(r["stage_seconds"]["check"])
                    stages["check_cpu_s"].append(r["stage_cpu_seconds"]["check"])
                    stages["read_s"].append(r["stage_seconds"]["read"])
                    stages["wall_s"].append(wall)
                entry = {k: spread(v) for k, v in stages.items()}
                entry["check_hexes_per_s"] = 27 * n ** 3 / entry["check_s"]["median"]
                checks[f"threads_{threads}"] = entry
            size["check_command_vtu"] = checks
            refines = {}
            for ext in ["vtu", "e"]:
                stages = {"wall_s": [], "ratio": [], "read_s": [], "refine_s": [], "check_s": [],
                          "write_s": [], "check_cpu_s": [], "write_cpu_s": []}
                for _ in range(args.runs):
                    out = tmp / f"r{n}.{ext}"
                    out.unlink(missing_ok=True)
                    report = tmp / "refine.json"
                    wall = run([hexrefine, "refine", brick, out, "--select", "all", "--method",
                                "selective", "--placement", "trilinear", "--threads", "2",
                                "--report", report])
                    r = json.loads(report.read_text())
                    versions.add(harness.report_schema_version(r))
                    seconds, cpu_seconds = r["stage_seconds"], r["stage_cpu_seconds"]
                    stages["wall_s"].append(wall)
                    stages["ratio"].append(wall / seconds["refine"])
                    for stage in ["read", "refine", "check", "write"]:
                        stages[f"{stage}_s"].append(seconds.get(stage, 0.0))
                    stages["check_cpu_s"].append(cpu_seconds.get("check", 0.0))
                    stages["write_cpu_s"].append(cpu_seconds.get("write", 0.0))
                refines[ext] = {k: spread(v) for k, v in stages.items()}
            size["refine_command_2_threads"] = refines
            record["sizes"][str(n)] = size
    record["load_average_after"] = load_average()
    record["schema_version"] = harness.schema_versions(versions)
    out_dir = pathlib.Path(args.out)
    harness.write_json_atomic(out_dir / "checker.json", record)
    harness.write_text_atomic(out_dir / "checker.md", markdown(record))
    print(markdown(record))


def markdown(record):
    lines = [
        f"From `experiments/studies/checker/run.py` (`checker.json`), {record['date']}, commit "
        f"`{record['commit'][:10]}`, {record['cores']} cores ({record['cpu']}), load average "
        f"{' '.join(map(str, record['load_average_before']))} before and "
        f"{' '.join(map(str, record['load_average_after']))} after; medians of "
        f"{record['runs']} runs, the range in brackets.", "",
        "| output hexes | checker | threads | real s | CPU s | M hexes/s | target |",
        "|---:|---|---:|---|---|---:|---|"]
    for n, size in record["sizes"].items():
        for name, b in size["bench_checker"]["benchmarks"].items():
            threads = 2 if name.endswith("2_threads") else 1
            kind = "against the input" if "against_input" in name else "no reference"
            real, cpu = b["real_s"], b["cpu_s"]
            target = (("met" if b["hexes_per_s"] >= 10e6 else "not met")
                      if threads == 2 else "")
            lines.append(
                f"| {size['hexes_out']:,} ({n}^3) | mesh_check, {kind} | {threads} | "
                f"{real['median']:.3f} [{real['min']:.3f}-{real['max']:.3f}] | "
                f"{cpu['median']:.3f} [{cpu['min']:.3f}-{cpu['max']:.3f}] | "
                f"{b['hexes_per_s'] / 1e6:.1f} | {target} |")
        for key, c in size["check_command_vtu"].items():
            threads = int(key.split("_")[1])
            s, cpu = c["check_s"], c["check_cpu_s"]
            lines.append(
                f"| {size['hexes_out']:,} ({n}^3) | `hexrefine check` .vtu, check stage | "
                f"{threads} | {s['median']:.3f} [{s['min']:.3f}-{s['max']:.3f}] | "
                f"{cpu['median']:.3f} [{cpu['min']:.3f}-{cpu['max']:.3f}] | "
                f"{c['check_hexes_per_s'] / 1e6:.1f} | |")
    lines += ["", "| output | command | wall s | refine stage s | wall / refine | read | check | "
              "write | check CPU s | write CPU s | target (<= 3) |",
              "|---|---|---|---|---|---:|---:|---:|---:|---:|---|"]
    for n, size in record["sizes"].items():
        for ext, r in size["refine_command_2_threads"].items():
            w, f, ratio = r["wall_s"], r["refine_s"], r["ratio"]
            lines.append(
                f"| {n}^3 -> .{ext} | `hexrefine refine --threads 2` | "
                f"{w['median']:.3f} [{w['min']:.3f}-{w['max']:.3f}] | "
                f"{f['median']:.3f} [{f['min']:.3f}-{f['max']:.3f}] | "
                f"{ratio['median']:.2f} [{ratio['min']:.2f}-{ratio['max']:.2f}] | "
                f"{r['read_s']['median']:.3f} | {r['check_s']['median']:.3f} | "
                f"{r['write_s']['median']:.3f} | {r['check_cpu_s']['median']:.3f} | "
                f"{r['write_cpu_s']['median']:.3f} | "
                f"{'met' if ratio['median'] <= 3 else 'not met'} |")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    main()
