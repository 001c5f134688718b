/// \file
/// libFuzzer target: Abaqus input (.inp). See fuzz_common.hpp and run_fuzzers.sh.

#include "tests/fuzz/fuzz_common.hpp"

HEXREFINE_FUZZ_TARGET("fuzz.inp")
