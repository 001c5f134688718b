#include "experiments/cli.hpp"
#include "mesh/error.hpp"

namespace hexrefine {

int cli_refine(const std::vector<std::string>& args) {
  (void)args;
  throw OperationError("hexrefine refine: not implemented yet");
}

}  // namespace hexrefine
