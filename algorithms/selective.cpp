#include "algorithms/selective.hpp"

#include "mesh/error.hpp"

namespace hexrefine {

RefineResult selective_refine(const HexMesh&, const Targets&, const RefineOptions&) {
  throw OperationError("selective refinement: not implemented yet");
}

}  // namespace hexrefine
