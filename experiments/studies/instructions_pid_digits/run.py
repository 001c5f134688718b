#!/usr/bin/env python3
"""How much the process id moves the instruction counts of `hexrefine bench --instructions`.

The writers name their temporary files after the process id (mesh/atomic_file.cpp), so a
workload that writes executes a few more instructions per digit of its pid: the one source of
run-to-run difference left in the counts. This runs each workload that writes or reads a file
(and one that does not) under Callgrind exactly as `hexrefine bench --instructions` does, once
as an ordinary process (a pid of 5 to 7 digits) and once as pid 1 of a new pid namespace
(`unshare --pid --fork`, needs root), and writes the counts and their differences to
results/bench/instructions_pid_digits.json (with the provenance).

Usage (after a Release build):
    python3 experiments/studies/instructions_pid_digits/run.py [BUILD_DIR] [--out results/bench]
"""
import os
import pathlib
import shutil
import subprocess
import sys
import tempfile

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent.parent))
import harness  # noqa: E402


def count(driver, shared, valgrind, name, namespace):
    """The workload's Callgrind total and the pid it ran with."""
    with tempfile.TemporaryDirectory(prefix="hexrefine_pid_") as folder:
        script = ('echo $$ > pid; exec "$0" --command-line-only=yes --tool=callgrind '
                  '--collect-atstart=no --toggle-collect=hexrefine_instruction_region '
                  '--dump-line=no --callgrind-out-file=cg.out "$1" --run "$2" --result r.json')
        command = ["env", "-i", "HEXREFINE_SHARED_DIR=" + shared, "/bin/bash", "-c", script,
                   valgrind, driver, name]
        if namespace:
            command = ["unshare", "--pid", "--fork"] + command
        subprocess.run(command, cwd=folder, check=True, capture_output=True)
        pid = int(open(os.path.join(folder, "pid")).read())
        for line in open(os.path.join(folder, "cg.out")):
            if line.startswith("totals:"):
                return int(line.split()[1]), pid
    raise RuntimeError(name + ": no totals line")


def main():
    parser = harness.study_arguments(harness.first_line(__doc__), out=harness.RESULTS / "bench")
    parser.add_argument("build", nargs="?", default=str(harness.REPO / "build"),
                        help="the Release build folder (default %(default)s)")
    args = parser.parse_args()
    driver = os.path.realpath(os.path.join(args.build, "experiments", "instruction_workloads"))
    shared = os.path.realpath(os.environ.get("HEXREFINE_SHARED_DIR", str(harness.SHARED)))
    valgrind = shutil.which("valgrind")
    workloads = [
        line
        for line in subprocess.run([driver, "--list"], check=True, capture_output=True,
                                   text=True, env={"HEXREFINE_SHARED_DIR": shared}).stdout.split()
        if line.startswith(("write/", "read/", "command/"))
        or line == "refine/radial_10/selective/trilinear"
    ]
    records = []
    for name in workloads:
        plain, plain_pid = count(driver, shared, valgrind, name, False)
        alone, alone_pid = count(driver, shared, valgrind, name, True)
        records.append({"name": name, "pid": plain_pid, "instructions": plain,
                        "pid_in_namespace": alone_pid, "instructions_in_namespace": alone,
                        "difference": plain - alone,
                        "relative_difference": abs(plain - alone) / plain,
                        "pid_digits_difference": len(str(plain_pid)) - len(str(alone_pid))})
        print(f"{name:55s} pid {plain_pid:>8} {plain:>14,}  pid {alone_pid} {alone:>14,}  "
              f"{plain - alone:+6d} ({records[-1]['relative_difference']:.2e})")
    harness.write_json_atomic(
        pathlib.Path(args.out) / "instructions_pid_digits.json",
        dict(harness.provenance(driver),
             valgrind=subprocess.run([valgrind, "--version"], capture_output=True,
                                     text=True).stdout.strip(),
             records=records,
             largest_relative_difference=max(r["relative_difference"] for r in records)),
        indent=2)


if __name__ == "__main__":
    main()
