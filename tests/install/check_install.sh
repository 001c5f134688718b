#!/usr/bin/env bash
# The installed package as a user gets it: `cmake --install` into a fresh prefix, then
#  1. the installed `hexrefine` command runs;
#  2. a ten-line consumer (tests/install/consumer) finds the package with find_package(hexrefine),
#     links hexrefine::hexrefine and refines the thesis' L-shaped case: 8060 hexes, valid;
#  3. the installed Python module imports from the prefix, outside the tree, and refines;
#  4. `pip install --no-build-isolation --no-index .` into a venv over Debian's packages, and the
#     module imported from the venv (HEXREFINE_CMAKE_BUILD_DIR: built in BUILD, not again).
# usage: check_install.sh BUILD SOURCE WORK   (WORK is emptied first)
set -euo pipefail
build=$(cd "$1" && pwd)
source=$(cd "$2" && pwd)
work=$3
rm -rf "$work"
mkdir -p "$work"
work=$(cd "$work" && pwd)
prefix=$work/prefix
fail() { echo "check_install: $*" >&2; exit 1; }

cmake --install "$build" --prefix "$prefix" > "$work/install.log"
[ -x "$prefix/bin/hexrefine" ] || fail "no $prefix/bin/hexrefine"
[ -f "$prefix/lib/cmake/hexrefine/hexrefineConfig.cmake" ] || fail "no package config"
[ -f "$prefix/include/hexrefine/algorithms/pipeline/pipeline.hpp" ] || fail "no headers"
"$prefix/bin/hexrefine" generate brick "$work/brick.mesh" --dims 2,2,2
"$prefix/bin/hexrefine" refine "$work/brick.mesh" "$work/brick.vtu" --method sheet --select all \
  --report "$work/brick.json"
grep -q '"final_hexes": 216' "$work/brick.json" || fail "installed command: not 216 hexes"

cmake -S "$source/tests/install/consumer" -B "$work/consumer" -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$prefix" > "$work/consumer.log"
cmake --build "$work/consumer" >> "$work/consumer.log"
out=$("$work/consumer/consumer")
[ "$out" = "8060 hexes, valid 1" ] || fail "consumer printed '$out'"

pydir=$(echo "$prefix"/lib/python3*/dist-packages)
[ -f "$pydir/hexrefine/__init__.py" ] || fail "no Python package under $prefix/lib"
program="
import sys, hexrefine
where = sys.argv[1]
assert hexrefine.__file__.startswith(where), hexrefine.__file__
mesh = hexrefine.generate('brick', dims=[3, 3, 3])
refined, report = hexrefine.refine(mesh, ['all'], method='sheet')
assert report['refine']['final_hexes'] == 729, report['refine']['final_hexes']
print('imported from', hexrefine.__file__)
"
(cd "$work" && PYTHONPATH="$pydir" /usr/bin/python3 -c "$program" "$prefix")

/usr/bin/python3 -m venv --system-site-packages "$work/venv"
(cd "$work" && HEXREFINE_CMAKE_BUILD_DIR="$build" "$work/venv/bin/pip" install -q \
  --no-build-isolation --no-index "$source" > "$work/pip.log" 2>&1) || {
  cat "$work/pip.log" >&2
  fail "pip install failed"
}
(cd "$work" && "$work/venv/bin/python" -c "$program" "$work/venv")
echo "check_install: command, CMake package, Python module (cmake --install and pip) all work"
