#!/usr/bin/env bash
# Measures the issue-7 performance targets and writes results/performance/*.json and
# results/performance.md. Needs a Release build with the benchmarks:
#   cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DHEXREFINE_BENCHMARKS=ON
#   make -C build -j2 hexrefine bench_refiners bench_topology
# Run it on an idle machine: about 10 minutes, up to 2 GB of memory.
set -euo pipefail
repo=$(cd "$(dirname "$0")/../../.." && pwd)
bin=$repo/build/experiments
out=$repo/results/performance
reps=${REPS:-5}
# The refiners on 25^3, 50^3 and 75^3 bricks: full refinement and the radial case, both
# methods, the round-by-round sheet path, and two threads.
HEXREFINE_BENCH_LARGE=1 "$bin/bench_refiners" \
  --benchmark_filter='bench_(full_brick|radial)/[a-z_0-9]+/(25|50|75)/' \
  --benchmark_repetitions="$reps" --benchmark_format=json > "$out/refiners.json.tmp"
mv "$out/refiners.json.tmp" "$out/refiners.json"
"$bin/bench_topology" --benchmark_filter='bench_topology_build' \
  --benchmark_repetitions="$reps" --benchmark_format=json > "$out/topology.json.tmp"
mv "$out/topology.json.tmp" "$out/topology.json"
# Peak memory of whole processes (/usr/bin/time -v): the refiner alone on 75^3 (the benchmark
# process: brick, refinement, one output), and the `hexrefine refine` command (read, refine,
# check, write).
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$bin/hexrefine" generate brick "$tmp/b75.mesh" --dims 75,75,75 > /dev/null
echo "{" > "$out/peak_memory.json.tmp"
first=1
for m in selective sheet; do
  rss() { grep 'Maximum resident' "$1" | awk '{print $6}'; }
  wall() { grep 'Elapsed (wall clock)' "$1" | awk '{print $8}'; }
  HEXREFINE_BENCH_LARGE=1 /usr/bin/time -v -o "$tmp/time.txt" "$bin/bench_refiners" \
    --benchmark_filter="bench_full_brick/$m/75/" > /dev/null 2>&1
  r1=$(rss "$tmp/time.txt")
  /usr/bin/time -v -o "$tmp/time.txt" "$bin/hexrefine" refine "$tmp/b75.mesh" "$tmp/out.mesh" \
    --method "$m" --select all > "$tmp/refine.txt" 2>&1
  r2=$(rss "$tmp/time.txt")
  w2=$(wall "$tmp/time.txt")
  [ $first = 1 ] || echo "," >> "$out/peak_memory.json.tmp"
  first=0
  printf '  "%s": {"refiner_process_max_rss_kB": %s, "refine_command_max_rss_kB": %s, "refine_command_wall": "%s", "refine_command_output": "%s"}' \
    "$m" "$r1" "$r2" "$w2" "$(tr -d '\n"' < "$tmp/refine.txt")" >> "$out/peak_memory.json.tmp"
done
printf '\n}\n' >> "$out/peak_memory.json.tmp"
mv "$out/peak_memory.json.tmp" "$out/peak_memory.json"
python3 "$repo/experiments/studies/performance/run.py"
