/// \file
/// libFuzzer target: Gmsh binary files (file type 1), seeded with 4.1 files written by hexrefine,
/// meshio and gmsh and 2.2 files written by meshio and gmsh. See fuzz_common.hpp and
/// run_fuzzers.sh.

#include "tests/fuzz/fuzz_common.hpp"

HEXREFINE_FUZZ_TARGET("fuzz.msh")
