#include "experiments/cli.hpp"
#include "mesh/error.hpp"

namespace hexrefine {

int cli_reproduce(const std::vector<std::string>& args) {
  (void)args;
  throw OperationError("hexrefine reproduce: not implemented yet");
}

}  // namespace hexrefine
