/// \file
/// libFuzzer target: Exodus II (.e): signature and header checks before libexodusii reads the data.
/// See fuzz_common.hpp and run_fuzzers.sh.

#include "tests/fuzz/fuzz_common.hpp"

HEXREFINE_FUZZ_TARGET("fuzz.e")
