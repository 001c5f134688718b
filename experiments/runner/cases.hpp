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

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace hexrefine {

/// The suite as a case file. `meshes_dir` is the path of ../shared/meshes as the case file will
/// see it (relative to the case file's folder, or absolute); `output` its "output". `quick`
/// stops the G-2 and G-3 sweeps at n = 30.
nlohmann::json thesis_suite_cases(bool quick, const std::string& meshes_dir,
                                  const std::string& output);

/// One mesh of the real-mesh study.
struct StudyMesh {
  std::string path;       ///< where this process reads it (absolute or relative to the cwd)
  std::string case_path;  ///< the same file as the case file names it ("file")
  std::string file;       ///< its file name, tagged "mesh" on every record
  std::string folder;     ///< its folder as given (tag "folder"): "../shared/meshes" or --meshes
  bool shared = true;     ///< from ../shared/meshes (tag "source": "shared"), else "meshes"
};

/// The arms of the study (issue 28, decisions 2 and 3), run on every (mesh, region kind, method):
/// "trilinear" (the thesis' placement, unsmoothed: refusals counted, allowed), "default" (no
/// placement given: the pipeline's default, unsmoothed) and "default-smooth" (no placement given,
/// smoothed: the pipeline picks its start for --smooth; the record's options.placement.method
/// says which). Each arm is a case of its own, so the unsmoothed arm's times are its own.
const std::vector<std::string>& study_arms();

/// The real-mesh study (`hexrefine study`): for each of `meshes` of at most `max_hexes_input`
/// hexes (read here for their size, bounding box and checker verdict; the others are left out and
/// named in `skipped`, as are unreadable files, "file: reason"), the region kinds sphere (a ball
/// about the bounding box's centre, radius 0.15 of its diagonal), grown blob (2 % of the hexes, at
/// least 20, two seeds), boundary surface (the largest patch at 30 degrees), scattered hexes (2 %,
/// two seeds) and two passes with the buffer (a ball of 0.1 of the diagonal), plus rockerarm.mesh's
/// sphere:0,0,0,5; both methods; each study_arms() arm. Tags: study "real_meshes", mesh, folder,
/// source, kind, arm, input_valid (the checker's verdict on the input; a refusal of a valid input
/// is a defect, of an invalid one the right answer) and input_defects. Case names: "FILE/KIND/ARM"
/// for shared meshes, "FOLDER:FILE/KIND/ARM" for the others. Then the anisotropy cases (tags study
/// "anisotropy", aspect, orientation, arm): one target hex in the middle of a 5x5x5 brick of boxes
/// 1 x 1 x a ("long") or a x a x 1 ("flat"), a in 1, 1.5, 2, 3, 4, the same arms.
nlohmann::json real_mesh_study_cases(const std::vector<StudyMesh>& meshes,
                                     const std::string& output, int64_t max_hexes_input = INT64_MAX,
                                     std::vector<std::string>* skipped = nullptr);

/// Sweep intervals: 5, 10, ..., 75 (quick: ..., 30).
std::vector<int> thesis_sweep_intervals(bool quick);

}  // namespace hexrefine
