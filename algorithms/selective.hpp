#pragma once
/// \file
/// The Selective Approach (Parrish, BYU MS thesis, chapter 5). See selective.cpp.

#include "algorithms/refiner.hpp"

namespace hexrefine {

/// Refines `targets` of `mesh` by the Selective Approach. Throws OperationError naming the hexes
/// when a configuration cannot be handled (never returns a broken mesh).
RefineResult selective_refine(const HexMesh& mesh, const Targets& targets,
                              const RefineOptions& options);

}  // namespace hexrefine
