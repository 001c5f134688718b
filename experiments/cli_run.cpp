#include "experiments/cli.hpp"
#include "mesh/error.hpp"

namespace hexrefine {

int cli_run(const std::vector<std::string>& args) {
  (void)args;
  throw OperationError("hexrefine run: not implemented yet");
}

}  // namespace hexrefine
