#pragma once
/// \file
/// Harris-style sheet refinement (thesis chapter 4, Appendices C and D). See sheet.cpp.

#include "algorithms/refiner.hpp"

namespace hexrefine {

/// Refines `targets` of `mesh` one direction at a time, sheet by sheet. Throws OperationError
/// naming the sheet and hexes for a case it refuses (never returns a broken mesh).
RefineResult sheet_refine(const HexMesh& mesh, const Targets& targets,
                          const RefineOptions& options);

}  // namespace hexrefine
