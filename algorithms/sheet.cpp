#include "algorithms/sheet.hpp"

#include "mesh/error.hpp"

namespace hexrefine {

RefineResult sheet_refine(const HexMesh&, const Targets&, const RefineOptions&) {
  throw OperationError("sheet refinement: not implemented yet");
}

}  // namespace hexrefine
