#include "experiments/cli.hpp"
#include "mesh/error.hpp"

namespace hexrefine {

int cli_check(const std::vector<std::string>& args) {
  (void)args;
  throw OperationError("hexrefine check: not implemented yet");
}

}  // namespace hexrefine
