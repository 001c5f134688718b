/// \file
/// libFuzzer target: VTK legacy, seeded with ASCII files. See fuzz_common.hpp and run_fuzzers.sh.

#include "tests/fuzz/fuzz_common.hpp"

HEXREFINE_FUZZ_TARGET("fuzz.vtk")
