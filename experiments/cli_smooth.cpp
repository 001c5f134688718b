#include "experiments/cli.hpp"
#include "mesh/error.hpp"

namespace hexrefine {

int cli_smooth(const std::vector<std::string>& args) {
  (void)args;
  throw OperationError("hexrefine smooth: not implemented yet");
}

}  // namespace hexrefine
