#include "experiments/cli.hpp"

int main(int argc, char** argv) {
  return hexrefine::cli_main(argc, argv);
}
