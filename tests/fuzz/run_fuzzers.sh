#!/usr/bin/env bash
# Builds the libFuzzer targets of the mesh readers (clang, ASan + UBSan) and runs each for
# SECONDS seconds on its corpus, JOBS targets at a time (default 2), then prints libFuzzer's
# final statistics per target: executions, coverage (cov = edges, ft = features), crashes.
#
#   tests/fuzz/run_fuzzers.sh SECONDS [TARGET ...]     e.g. tests/fuzz/run_fuzzers.sh 30
#
# Environment: FUZZ_BUILD_DIR (default <repo>/build-fuzz), CLANG_CXX / CLANG_CC (default
# clang++-14 / clang-14), JOBS (default 2), FUZZ_RSS_MB (default 1024).
# Seeds: tests/fuzz/corpus/<format>/ (committed, read only). New inputs libFuzzer finds go to
# $FUZZ_BUILD_DIR/fuzz-corpus/<format>/ and crash/timeout/oom inputs to
# $FUZZ_BUILD_DIR/fuzz-artifacts/<format>/; a crash file belongs in tests/fuzz/crashes/ once fixed
# (test_io_fuzz_regressions.cpp reads every file there). Exit status 1 if any target found
# something in this run (a non-zero libFuzzer exit or a new file in its artifact folder): the
# path of each such input and the end of the target's log are printed, so a CI log shows what
# to reproduce with `$FUZZ_BUILD_DIR/tests/fuzz/fuzz_<format> <input>`; 2 if the build failed.
set -u
if [ $# -lt 1 ] || ! [[ "$1" =~ ^[0-9]+$ ]]; then
  echo "usage: $0 SECONDS [TARGET ...]  (targets: medit vtk_ascii vtk_binary vtu gmsh22 gmsh41 gmsh_binary abaqus exodus)" >&2
  exit 2
fi
seconds=$1
shift
here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/../.." && pwd)
build=${FUZZ_BUILD_DIR:-$repo/build-fuzz}
cxx=${CLANG_CXX:-clang++-14}
cc=${CLANG_CC:-clang-14}
jobs=${JOBS:-2}
rss=${FUZZ_RSS_MB:-1024}
targets=("$@")
[ ${#targets[@]} -eq 0 ] && targets=(medit vtk_ascii vtk_binary vtu gmsh22 gmsh41 gmsh_binary abaqus exodus)

if ! command -v "$cxx" > /dev/null; then
  echo "$0: $cxx not found: the fuzzers need clang with libFuzzer (CLANG_CXX=...)" >&2
  exit 2
fi

mkdir -p "$build"
CC=$cc CXX=$cxx cmake -S "$repo" -B "$build" -DHEXREFINE_FUZZ=ON -DHEXREFINE_BENCHMARKS=OFF > "$build/fuzz-cmake.log" 2>&1 || {
  cat "$build/fuzz-cmake.log" >&2
  exit 2
}
make -C "$build" -j"$jobs" $(printf 'fuzz_%s ' "${targets[@]}") > "$build/fuzz-build.log" 2>&1 || {
  tail -40 "$build/fuzz-build.log" >&2
  exit 2
}

dict_of() {
  case $1 in
    vtk_ascii | vtk_binary) echo vtk ;;
    gmsh22 | gmsh41 | gmsh_binary) echo gmsh ;;
    *) echo "$1" ;;
  esac
}

run_one() {
  local t=$1
  local work="$build/fuzz-corpus/$t" art="$build/fuzz-artifacts/$t/"
  mkdir -p "$work" "$art"
  # Inputs kept from earlier runs are not this run's findings: only files newer than this mark.
  touch "$build/fuzz-$t.start"
  # UBSan: stop at the first report so it counts as a crash.
  UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 ASAN_OPTIONS=detect_leaks=1 \
    "$build/tests/fuzz/fuzz_$t" "$work" "$here/corpus/$t" \
    -dict="$here/dict/$(dict_of "$t").dict" -max_total_time="$seconds" -print_final_stats=1 \
    -max_len=16384 -timeout=10 -rss_limit_mb="$rss" -artifact_prefix="$art" \
    > "$build/fuzz-$t.log" 2>&1
  echo $? > "$build/fuzz-$t.rc"
}

running=0
for t in "${targets[@]}"; do
  run_one "$t" &
  running=$((running + 1))
  if [ "$running" -ge "$jobs" ]; then
    wait -n
    running=$((running - 1))
  fi
done
wait

status=0
printf '%-11s %8s %12s %9s %7s %7s %8s  %s\n' target seconds executions exec/s cov ft corpus result
for t in "${targets[@]}"; do
  log="$build/fuzz-$t.log"
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
  last=$(grep -E '^#[0-9]+' "$log" | tail -1)
  cov=$(echo "$last" | sed -n 's/.*cov: \([0-9]*\).*/\1/p')
  ft=$(echo "$last" | sed -n 's/.*ft: \([0-9]*\).*/\1/p')
  corp=$(echo "$last" | sed -n 's/.*corp: \([0-9]*\).*/\1/p')
  rc=$(cat "$build/fuzz-$t.rc" 2>/dev/null || echo "?")
  found=$(find "$build/fuzz-artifacts/$t/" -type f -newer "$build/fuzz-$t.start" 2>/dev/null | wc -l)
  result=ok
  if [ "$rc" != 0 ] || [ "$found" -gt 0 ]; then
    result="FOUND $found input(s) in $build/fuzz-artifacts/$t/ (rc $rc, see $log)"
    status=1
  fi
  printf '%-11s %8s %12s %9s %7s %7s %8s  %s\n' "$t" "$seconds" "${execs:-?}" "${rate:-?}" \
    "${cov:-?}" "${ft:-?}" "${corp:-?}" "$result"
done
for t in "${targets[@]}"; do
  rc=$(cat "$build/fuzz-$t.rc" 2>/dev/null || echo "?")
  inputs=$(find "$build/fuzz-artifacts/$t/" -type f -newer "$build/fuzz-$t.start" 2>/dev/null)
  if [ "$rc" != 0 ] || [ -n "$inputs" ]; then
    echo
    echo "=== fuzz_$t found something (libFuzzer exit $rc); input(s):"
    for f in $inputs; do echo "  $f"; done
    echo "--- end of $build/fuzz-$t.log:"
    tail -40 "$build/fuzz-$t.log"
  fi
done
exit $status
