#!/usr/bin/env bash
# Measures the issue-14 end-to-end targets: the `hexrefine refine` command on a 75^3 brick (all
# hexes, Selective Approach, trilinear placement) to Exodus II, to VTU and to binary Gmsh 4.1,
# one and two threads, and `hexrefine check` of its 11.4 M-hex output in each format; wall time, stage times (--report) and peak
# memory (/usr/bin/time -v) of each command, output sizes, and the floor of this machine's file
# system: the time `dd` takes to write as many bytes into the page cache, and how fast fresh
# memory is first touched (1 GiB twice in one process). Every command runs RUNS times (default
# 3) back to back; the report (experiments/studies/performance/run.py) shows the median run and
# the spread. Each refine run starts without its output file: replacing an existing 1 GB file
# frees its page cache inside the rename, which is the file system's cost, not the command's.
# Writes results/performance/command.json; the report turns it into a section of
# results/performance.md.
# Needs a Release build (cmake -S . -B build -DCMAKE_BUILD_TYPE=Release && make -C build hexrefine)
# and about 3 GB of memory and 4 GB of disk in $TMPDIR; about 8 minutes on an idle machine.
set -euo pipefail
repo=$(cd "$(dirname "$0")/../../.." && pwd)
bin=$repo/build/experiments/hexrefine
# OUT: another output file, e.g. for a run with HEXREFINE_HUGE_PAGES=0 (4 KiB pages), which
# the report (experiments/studies/performance/run.py) compares with command.json.
out=${OUT:-$repo/results/performance/command.json}
repeats=${RUNS:-3}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$bin" generate brick "$tmp/b75.e" --dims 75,75,75 > /dev/null
runs=()
# run NAME COMMAND...: the command's wall time and peak memory, its report if it wrote one.
run() {
  local name=$1
  shift
  rm -f "$tmp/$name.json"
  /usr/bin/time -v -o "$tmp/$name.time" "$@" > /dev/null 2> "$tmp/$name.err" || {
    cat "$tmp/$name.err" >&2
    exit 1
  }
  local wall peak report="null"
  wall=$(grep 'Elapsed (wall clock)' "$tmp/$name.time" | awk '{print $NF}' |
    awk -F: '{ if (NF == 3) print $1 * 3600 + $2 * 60 + $3; else print $1 * 60 + $2 }')
  peak=$(grep 'Maximum resident' "$tmp/$name.time" | awk '{print $6}')
  [ -f "$tmp/$name.json" ] && report=$(cat "$tmp/$name.json")
  runs+=("{\"name\": \"$name\", \"wall_s\": $wall, \"peak_rss_MB\": $((peak / 1024)), \"report\": $report}")
}
# First touch of fresh memory, 1 GiB filled twice in one process (glibc's huge pages asked for,
# as the command does): on a virtual machine whose host backs guest memory lazily (or takes
# freed pages back, free page reporting) the first fill can cost several times the second.
# Measured first, in the state the first command meets.
first_touch=$(GLIBC_TUNABLES=glibc.malloc.hugetlb=1 python3 -c '
import time
times = []
for _ in range(2):
    start = time.perf_counter()
    block = bytearray(b"\x01") * (1 << 30)
    times.append(time.perf_counter() - start)
    del block
print(f"[{times[0]:.3f}, {times[1]:.3f}]")')
for threads in 1 2; do
  for ext in e vtu msh; do
    switch=()
    [ "$ext" = msh ] && switch=(--binary)
    for ((repeat = 0; repeat < repeats; repeat++)); do
      rm -f "$tmp/out.$ext"
      run "refine_${ext}_threads_$threads" "$bin" refine "$tmp/b75.e" "$tmp/out.$ext" \
        --method selective --select all --placement trilinear --threads "$threads" "${switch[@]}" \
        --report "$tmp/refine_${ext}_threads_$threads.json"
    done
  done
done
# The issue's own check case: binary legacy VTK, made by `convert` (timed too: 10.7 s before).
for ((repeat = 0; repeat < repeats; repeat++)); do
  rm -f "$tmp/out.vtk"
  run convert_e_to_vtk_threads_1 "$bin" convert "$tmp/out.e" "$tmp/out.vtk" --binary
done
size_e=$(stat -c %s "$tmp/out.e")
size_vtu=$(stat -c %s "$tmp/out.vtu")
size_msh=$(stat -c %s "$tmp/out.msh")
for threads in 1 2; do
  for ext in e vtu msh vtk; do
    for ((repeat = 0; repeat < repeats; repeat++)); do
      run "check_${ext}_threads_$threads" "$bin" check "$tmp/out.$ext" --threads "$threads" \
        --report "$tmp/check_${ext}_threads_$threads.json"
    done
  done
done
# The file-system floor: writing size_e bytes of zeros into the page cache (no computation).
start=$(date +%s%N)
dd if=/dev/zero of="$tmp/floor" bs=16M count=$(((size_e + 16777215) / 16777216)) status=none
end=$(date +%s%N)
floor=$(awk "BEGIN { print ($end - $start) / 1e9 }")
{
  echo "{"
  echo "  \"date\": \"$(date -u +%Y-%m-%dT%H:%M:%SZ)\", \"commit\": \"$(git -C "$repo" rev-parse HEAD)\","
  echo "  \"cpus\": $(nproc), \"load_average\": \"$(cut -d' ' -f1-3 /proc/loadavg)\","
  echo "  \"huge_pages_opt_out\": \"${HEXREFINE_HUGE_PAGES:-}\","
  echo "  \"output_bytes\": {\"e\": $size_e, \"vtu\": $size_vtu, \"msh\": $size_msh, \"vtk\": $(stat -c %s "$tmp/out.vtk")},"
  echo "  \"page_cache_write_floor_s\": $floor,"
  echo "  \"first_touch_1GiB_s\": $first_touch,"
  echo "  \"repeats\": $repeats,"
  echo "  \"runs\": ["
  for i in "${!runs[@]}"; do
    [ "$i" -gt 0 ] && echo ","
    echo "    ${runs[$i]}"
  done
  echo "  ]"
  echo "}"
} > "$out.tmp"
python3 -c "import json,sys; json.load(open(sys.argv[1]))" "$out.tmp"
mv "$out.tmp" "$out"
echo "wrote $out"
