/// \file
/// libFuzzer target: Gmsh, seeded with version 2.2 files. See fuzz_common.hpp and run_fuzzers.sh.

#include "tests/fuzz/fuzz_common.hpp"

HEXREFINE_FUZZ_TARGET("fuzz.msh")
