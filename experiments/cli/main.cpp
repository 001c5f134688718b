#include "experiments/bench/process_huge_pages.hpp"
#include "experiments/cli/cli.hpp"

int main(int argc, char** argv) {
  hexrefine::process_prefer_huge_pages(argv);
  return hexrefine::cli_main(argc, argv);
}
