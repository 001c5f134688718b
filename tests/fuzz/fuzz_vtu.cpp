/// \file
/// libFuzzer target: VTK XML unstructured grid (.vtu). See fuzz_common.hpp and run_fuzzers.sh.

#include "tests/fuzz/fuzz_common.hpp"

HEXREFINE_FUZZ_TARGET("fuzz.vtu")
