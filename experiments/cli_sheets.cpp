#include "experiments/cli.hpp"
#include "mesh/error.hpp"

namespace hexrefine {

int cli_sheets(const std::vector<std::string>& args) {
  (void)args;
  throw OperationError("hexrefine sheets: not implemented yet");
}

}  // namespace hexrefine
