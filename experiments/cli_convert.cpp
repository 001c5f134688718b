#include "experiments/cli.hpp"
#include "mesh/error.hpp"

namespace hexrefine {

int cli_convert(const std::vector<std::string>& args) {
  (void)args;
  throw OperationError("hexrefine convert: not implemented yet");
}

}  // namespace hexrefine
