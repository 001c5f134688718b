#include "experiments/cli.hpp"
#include "mesh/error.hpp"

namespace hexrefine {

int cli_merge(const std::vector<std::string>& args) {
  (void)args;
  throw OperationError("hexrefine merge: not implemented yet");
}

}  // namespace hexrefine
