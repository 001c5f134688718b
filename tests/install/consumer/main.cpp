// Refines the L-shaped case (the thesis' G-1) through the installed library.
#include <iostream>

#include "algorithms/pipeline/pipeline.hpp"
#include "mesh/generators.hpp"

int main() {
  hexrefine::PipelineOptions options;
  options.select = {"boundary:-1,0,0", "boundary:0,0,-1"};
  const hexrefine::PipelineResult r =
      hexrefine::pipeline_run(hexrefine::generate_brick({.dims = {10, 10, 10}}), options);
  std::cout << r.stats.final_hexes << " hexes, valid " << r.check.valid() << "\n";
}
