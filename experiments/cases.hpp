#pragma once
/// \file
/// The built-in thesis suite (`hexrefine reproduce`): the cases of Parrish's chapter 6 and
/// Appendices G and H, rebuilt from what the thesis describes, both methods on the same targets.
///
/// Choices where the thesis gives no geometry (documented in results/README.md too):
/// - G-1: 10x10x10 unit brick, targets = hexes on the left (x-min) and bottom (z-min) surfaces.
/// - G-2: n x n x n unit brick, every hex; n = 5, 10, ..., 75.
/// - G-3: n x n x n unit brick, `sphere:1,0,1,0.5`: radius 0.5 about the top front right
///   vertex (1, 0, 1) ("top" = z-max, "front" = y-min, "right" = x-max, as mesh/generators.hpp);
///   the brick and the radius stay fixed while n grows, as in the thesis.
/// - 6-1: generate_stepped's defaults (1,188 unit cubes), `boundary:1,0,0` (the right risers).
/// - 6-2 (quarter piston, top surfaces, smoothed): ellipsoid.mesh, `boundary:0,0,1,45` (boundary
///   faces facing up within 45 degrees), smoothed afterwards.
/// - H-1: generate_gear's defaults (8,568 hexes), `block:2` (the teeth), smoothed afterwards.
/// - H-2: 4x4x4 unit brick, `boundary:-1,0,0`, 3 passes, with the thesis' buffer rule
///   (PassBuffer::layer), and as ablations "H-2/none" and "H-2/transitions".
/// - H-3 (mechanical plate, neck region): cube_minus_sphere_conforming.mesh,
///   `sphere:0.275,0.275,0,0.15` (a ball about the middle of one of the cube's edges); the
///   selective method is expected to refuse it with trilinear placement ("expect").
/// - H-4 (hook, every hex): rockerarm.mesh, `all`.
/// - real/ellipsoid-sphere: ellipsoid.mesh, `sphere:0,0,0,0.15` (an interior ball).
/// - Ablations (selective only): ranking off, propagation off, element-by-element only, on G-1
///   and on G-3 with n = 20.

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace hexrefine {

/// The suite as a case file. `meshes_dir` is the path of ../shared/meshes as the case file will
/// see it (relative to the case file's folder, or absolute); `output` its "output". `quick`
/// stops the G-2 and G-3 sweeps at n = 30.
nlohmann::json thesis_suite_cases(bool quick, const std::string& meshes_dir,
                                  const std::string& output);

/// The real-mesh study (`hexrefine study`): for each of `mesh_files` (names in `meshes_read_dir`,
/// read here for their bounding boxes; `meshes_dir` is that folder as the case file sees it), the
/// region kinds sphere (a ball about the bounding box's centre, radius 0.15 of its diagonal), grown
/// blob (2 % of the hexes, at least 20, two seeds), boundary surface (the largest patch at 30
/// degrees), scattered hexes (2 %, two seeds) and two passes with the buffer (a ball of 0.1 of the
/// diagonal), plus rockerarm.mesh's sphere:0,0,0,5; both methods, trilinear and optimized
/// placement, smoothed (the record keeps the unsmoothed check too). Then the anisotropy cases
/// (tags study "anisotropy", aspect, orientation): one target hex in the middle of a 5x5x5 brick
/// of boxes 1 x 1 x a ("long") or a x a x 1 ("flat"), a in 1, 1.5, 2, 3, 4, the same options.
nlohmann::json real_mesh_study_cases(const std::vector<std::string>& mesh_files,
                                     const std::string& meshes_read_dir,
                                     const std::string& meshes_dir, const std::string& output);

/// Sweep intervals: 5, 10, ..., 75 (quick: ..., 30).
std::vector<int> thesis_sweep_intervals(bool quick);

}  // namespace hexrefine
