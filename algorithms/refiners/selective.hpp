#pragma once
/// \file
/// The Selective Approach (Parrish, BYU MS thesis, chapter 5). See selective.cpp.

#include "algorithms/refiners/refiner.hpp"

namespace hexrefine {

/// Decides one pass of the Selective Approach (RefinePlanFn): 1-27 on the targets, the
/// element-by-element template on each transition hex that has one, directional refinement of
/// the others (a template of its cells per hex), the adjustments' aliases; every template from
/// `templates`.
RefinementPlan selective_plan(const HexMesh& mesh, const HexTopology& topology,
                              const std::vector<int32_t>& targets, const RefineOptions& options,
                              RefineStats& stats, const TemplateLibrary& templates);

/// refine(refine_method("selective"), mesh, targets, options).
RefineResult selective_refine(const HexMesh& mesh, const Targets& targets,
                              const RefineOptions& options);

}  // namespace hexrefine
