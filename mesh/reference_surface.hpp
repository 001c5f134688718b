#pragma once
/// \file
/// The boundary surface of a reference mesh (the input of a refinement) and the one test of
/// whether a boundary face of a derived mesh lies on it. The checker (conformity.hpp) rejects
/// the boundary faces this test fails; smoothing keeps every boundary face it moves passing it
/// (smoothing.hpp), so that `refine --smooth` and `check --reference` agree by construction.

#include <cstdint>
#include <memory>
#include <vector>

#include "mesh/hex_mesh.hpp"
#include "mesh/quad_grid.hpp"
#include "mesh/quad_patch.hpp"

namespace hexrefine {

/// The reference's boundary quads (outward from their hex), each with its tolerance
/// (mesh_check_surface_tolerance x its diameter + its warp: a point averaged from patch points
/// can leave a warped patch by up to its warp), and a hash grid over them. Neither copyable nor
/// movable: the grid refers to the vectors.
class ReferenceSurface {
 public:
  /// Builds the surface of `reference` (its boundary faces: faces of one hex) on up to `threads`
  /// threads. Linear in the reference. Precondition: mesh_validate_ids(reference).
  ReferenceSurface(const HexMesh& reference, int threads = 1);
  ReferenceSurface(const ReferenceSurface&) = delete;
  ReferenceSurface& operator=(const ReferenceSurface&) = delete;

  const std::vector<Quad>& quads() const { return quads_; }
  const std::vector<double>& tolerances() const { return tolerances_; }
  const QuadGrid& grid() const { return *grid_; }

 private:
  std::vector<Quad> quads_;
  std::vector<double> tolerances_;
  std::unique_ptr<QuadGrid> grid_;
};

/// Whether boundary face `q` (corners in cyclic order) lies on `reference`, the checker's test
/// (conformity.hpp, "With a reference"): its four corners and centroid on one reference face
/// (within that face's tolerance), or across reference faces: each corner on a reference face
/// whose normal is within mesh_check_across_angle_degrees of q's, and the centroid within
/// mesh_check_across_chord x q's diameter of a reference face near it. A degenerate q (zero
/// normal) lies across nothing. Conservative: a reference face registered in none of the cells
/// looked at is missed (q is then rejected, never the reverse).
bool reference_surface_holds_face(const ReferenceSurface& reference, const Quad& q);

}  // namespace hexrefine
