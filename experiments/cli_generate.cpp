#include "experiments/cli.hpp"
#include "mesh/error.hpp"

namespace hexrefine {

int cli_generate(const std::vector<std::string>& args) {
  (void)args;
  throw OperationError("hexrefine generate: not implemented yet");
}

}  // namespace hexrefine
