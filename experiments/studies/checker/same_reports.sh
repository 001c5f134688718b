#!/usr/bin/env bash
# Issue 32, "same verdicts and counts": runs the checker of BASE (a commit, default bb967b0, the
# checker before the speed work) and of the working tree on the same meshes (the full
# refinements of 50^3 and 75^3 bricks without and with the brick as the reference, and every
# mesh of ../shared/meshes) and compares their JSON reports field for field (the field
# self_contact_faces, which BASE does not have, left out; floating-point values compared as
# printed with 17 digits, i.e. bit for bit). Writes results/performance/checker_same_reports.json.
# Needs a Release build of the working tree (build/mesh/libhexrefine_mesh.a, build/experiments/hexrefine);
# compiles BASE's mesh/ sources (git archive) into a temporary folder. About five minutes.
set -euo pipefail
repo=$(cd "$(dirname "$0")/../../.." && pwd)
base=${1:-bb967b0}
shared=${HEXREFINE_SHARED_DIR:-$repo/../shared}
[ -d "$shared/meshes" ] || shared=/work/shared
out=$repo/results/performance/checker_same_reports.json
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cat > "$tmp/dump.cpp" <<'EOF'
#include <cstdlib>
#include <iostream>
#include "mesh/conformity.hpp"
#include "mesh/io.hpp"
using namespace hexrefine;
// dump MESH THREADS [REFERENCE]: the checker's JSON report on stdout.
int main(int argc, char** argv) {
  const HexMesh mesh = mesh_read(argv[1]);
  HexMesh reference;
  if (argc > 3) reference = mesh_read(argv[3]);
  nlohmann::json j = mesh_check(mesh, argc > 3 ? &reference : nullptr, std::atoi(argv[2]));
  j.erase("self_contact_faces");
  std::cout << j.dump() << "\n";
}
EOF
libs="-lexoIIv2c -lnetcdf -lz -lOpenMeshCore"
mkdir -p "$tmp/base"
git -C "$repo" archive "$base" mesh | tar -x -C "$tmp/base"
(cd "$tmp/base" && ls mesh/*.cpp | xargs -P "$(nproc)" -I{} \
  g++ -std=c++20 -O3 -DNDEBUG -I. -isystem /usr/include/eigen3 -c {} -o {}.o &&
  ar rcs libmesh.a mesh/*.o)
g++ -std=c++20 -O3 -DNDEBUG -I"$tmp/base" -isystem /usr/include/eigen3 "$tmp/dump.cpp" \
  "$tmp/base/libmesh.a" $libs -o "$tmp/dump_base"
g++ -std=c++20 -O3 -DNDEBUG -I"$repo" -isystem /usr/include/eigen3 "$tmp/dump.cpp" \
  "$repo/build/mesh/libhexrefine_mesh.a" $libs -o "$tmp/dump_new"
bin=$repo/build/experiments/hexrefine
cases=()
for n in 50 75; do
  "$bin" generate brick "$tmp/b$n.e" --dims "$n,$n,$n" > /dev/null
  "$bin" refine "$tmp/b$n.e" "$tmp/o$n.vtu" --select all --method selective \
    --placement trilinear --threads 2 > /dev/null
  cases+=("$tmp/o$n.vtu 2" "$tmp/o$n.vtu 2 $tmp/b$n.e")
done
for mesh in "$shared"/meshes/*.{mesh,e,inp}; do cases+=("$mesh 2"); done
echo "[" > "$out.tmp"
first=1
for c in "${cases[@]}"; do
  # shellcheck disable=SC2086
  a=$("$tmp/dump_base" $c)
  # shellcheck disable=SC2086
  b=$("$tmp/dump_new" $c)
  same=false
  [ "$a" = "$b" ] && same=true
  name=$(echo "$c" | sed "s|$tmp/||g; s|$shared/meshes/||")
  [ $first = 1 ] || echo "," >> "$out.tmp"
  first=0
  printf '{"case": "%s", "identical": %s, "report": %s}' "$name" "$same" "$b" >> "$out.tmp"
  echo "$name: identical=$same"
done
echo "]" >> "$out.tmp"
python3 -c "import json,sys; json.dump({'base': sys.argv[2], 'cases': json.load(open(sys.argv[1]))}, open(sys.argv[3], 'w'), indent=1)" \
  "$out.tmp" "$base" "$out"
rm -f "$out.tmp"
