#pragma once
/// \file
/// Conformity and validity checks of an all-hex mesh, independent of how the mesh was made (it
/// knows nothing of the refiners). Every item is a count, not only a flag, so ablations can measure
/// how far from conformal a result is.
///
/// Definitions (all tolerances relative, so the checks are scale-free):
/// - non-manifold face: a quad (same four nodes) used by more than two hexes.
/// - non-conformal face: a boundary face (used by one hex) that is not a true boundary face.
///   * With a reference (the mesh before refinement): a boundary face whose four corners and
///     centroid do not all lie on one boundary face of the reference, and that does not lie
///     across reference faces either. Refinement must subdivide the reference's boundary faces,
///     so any other boundary face is one side of a gap between two hexes that should share a
///     face (the T-junction faces of a 1-8 split beside an unsplit hex: the big face and its
///     four small faces are all non-conformal). "Across": smoothing slides the input's own
///     boundary nodes over the input's faces (smoothing.cpp), so a face may span two of them;
///     it lies across them when each corner lies on a reference face whose normal is within
///     mesh_check_across_angle_degrees of the face's (a gap face through a one-hex-thick plate
///     has its corners on the surface too, but stands across it) and its centroid is within
///     mesh_check_across_chord x its diameter of one of those faces (the sag of a chord over a
///     bend of at most the smoothing's feature angle).
///   * Without a reference: a boundary face that, with another boundary face of the same mesh,
///     forms the two sides of a gap. Two boundary faces A and B touch when
///       (1) every corner of A is a node of B or lies on B (within
///           mesh_check_surface_tolerance x B's longer diagonal: no warp term, see below),
///       (2) they face each other: A's normal and B's patch normal where A's centroid projects
///           have a negative dot product, and
///       (3) A's hex lies beyond B: the centroid of the face opposite A in A's hex is on B's
///           outer side (farther than the tolerance along B's normal there).
///     Two neighbouring faces of a valid surface share an edge and their normals point the same
///     way, so (2) never holds for them; where the surface folds back on itself (a sharp edge,
///     a thin wedge) the normals oppose, but the hex between them lies on B's inner side, so (3)
///     fails; and (1) asks every corner to lie within 1e-6 of B's size of B, so a V-notch, whose
///     two faces share the notch's edge and face each other, counts only once it has closed to
///     that (a crack). Faces that touch
///     are linked; the linked groups are contact patches. A patch is a gap (its faces are
///     non-conformal) when, in some touching pair, the faces share a node or a corner of one is
///     at a corner of the other (a node split in two): the T-junction pocket of a hex split 1-8
///     beside an unsplit one (the big face shares its corners with the small faces), a crack
///     whose nodes were duplicated. Otherwise it is self-contact (self_contact_faces): two parts
///     of the boundary touching with no node between them, which is what a contact of two bodies
///     or of a part with itself looks like.
///     Choice: self-contact does not make a mesh invalid. Every hex face is matched or on the
///     boundary, so the hexes are conformal; the contact is a property of the domain (a mesher's
///     output of touching geometry), which a refinement keeps (it subdivides the boundary faces,
///     and its output is checked against the input). It is reported under its own count, and
///     `hexrefine check` names it. What it cannot be told from: a gap whose two sides share no
///     node and no corner position (two meshes laid against each other) is self-contact here.
///     The tolerance has no warp term (the former test accepted a centroid within the warp of
///     another face, and on a strongly warped face that band swallowed the centroid of the
///     neighbour across an edge: ecr_dragon.mesh hex 11999, ecr_cap.mesh): a gap's sides
///     coincide node for node (split nodes) or its hanging nodes lie on the big face's patch
///     (where a trilinear map or a slide on the patch puts them). A gap that leaves neither
///     (one hex moved away from its neighbour; a T-junction whose hanging nodes are off the
///     big face by more than the tolerance) cannot be told from true boundary without a
///     reference and is not detected: the checks of a refinement run against its input.
///   "Lies on a face" (with a reference; hanging nodes) = distance to the face's bilinear patch
///   <= mesh_check_surface_tolerance times the face's longer diagonal, plus the face's warp
///   (out-of-plane spread of its corners): on a warped face a centroid of patch points, or a node
///   a template placed on a child's patch in a later pass, is off the input's patch by up to the
///   warp, and must not be mistaken for a gap.
/// - hanging node (T-junction): a node of a non-conformal face that lies on another non-conformal
///   face B, is not one of B's nodes, and is farther than the tolerance from each of B's corners
///   (a different node at a corner's position is a duplicate node, not a hanging node). Each node
///   counted once. For a hex split 1-8 beside an unsplit hex: 5 (4 edge midpoints, 1 face centre).
/// - non-manifold boundary edge: an edge of a boundary face that does not lie in exactly two
///   boundary faces (the boundary surface is not a closed 2-manifold there).
/// - doublet: a pair of distinct hexes sharing two or more faces (counted once per pair).
/// - inverted hex: hex_scaled_jacobian <= 0 (inverted or degenerate).
/// - body: a connected component of the hexes under "shares a node" (a union-find over the
///   nodes, one pass over the hexes). A mesh of several bodies (parts glued or in contact along
///   coincident faces with unmerged nodes, as Sierra, Peridigm and MFEM contact meshes are) is
///   valid: a touching pair of faces joined by a corner on a corner (the unmerged nodes of a
///   glued interface, matching or not), or a coincident pair of nodes, whose two sides lie in
///   different bodies is an interface (interface_faces, interface_nodes), never a defect, and its
///   faces are no gap (nor their nodes hanging). A touching pair of two bodies with no corner on
///   a corner stays self-contact (a contact, not a glue). Within one body they stay what they
///   were (a crack's split faces and nodes: its cracked hex still shares the nodes of its other
///   faces with its neighbours, so it stays in the body).
/// - duplicate node: a node within 1e-12 x (bounding-box diagonal) of a node with a lower id of
///   the same body (see body; an unused node counts as of every body, so near a used node it is
///   a duplicate, as in a mesh of one body).
/// - unused node: a node no hex refers to.
/// - self-contact face: see "Without a reference" above (not examined with a reference, whose
///   boundary the output's is compared with instead).
/// conformal = no non-manifold faces, no non-conformal faces, no hanging nodes, no non-manifold
/// boundary edges and no doublets. Duplicate nodes, unused nodes and self-contact are reported,
/// and make no mesh invalid.
///
/// Reference comparison: total volume (sum of hex_volume) and boundary area (sum of the bilinear
/// patch areas of the boundary faces) are compared with the reference's. If every boundary quad of
/// the reference is planar (out-of-plane spread <= 1e-12 x its diagonal), refinement must preserve
/// both to mesh_check_geometry_tolerance relative; otherwise the errors are only reported.
///
/// Time: linear in the mesh size, every pass on up to `threads` threads: one pass over the hexes
/// (their ids, the nodes they use, the scaled Jacobian, volume and edge ratio from one gather of
/// their corners, four hexes per evaluation where the machine has AVX2: mesh_hex_measures),
/// faces matched by hex_face_adjacency_build (a counting sort of the face slots by lowest node;
/// no general topology), duplicate nodes by a counting sort of the points into cells compared on
/// float keys, boundary edges counted by a radix sort of their keys, hash grids over the
/// boundary faces for the geometric tests, and bodies by a union-find over the nodes (one serial
/// pass over the hexes, 4 bytes per node; labels only when there are several bodies). Memory at
/// its peak: about 32 bytes per hex beyond the
/// mesh itself (the face slots and the per-thread bucket counts; doublets are found while
/// matching, without a neighbour array). Every figure of the report is the same for any thread
/// count (sums per fixed chunk, combined in chunk order).
/// Not done: certifying only the part a refinement changed. The checker knows nothing of how a
/// mesh was made, and a full refinement (the case measured in results/performance.md) changes
/// every hex, so there would be nothing to skip.

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "mesh/hex_mesh.hpp"

namespace hexrefine {

/// Relative distance under which a point counts as lying on a boundary face.
inline constexpr double mesh_check_surface_tolerance = 1e-6;
/// A boundary face across reference faces: largest angle between its normal and theirs, and
/// largest distance of its centroid from them relative to its diameter (see above).
inline constexpr double mesh_check_across_angle_degrees = 45;
inline constexpr double mesh_check_across_chord = 0.1;
/// Relative volume and boundary-area error allowed for planar-faced references.
inline constexpr double mesh_check_geometry_tolerance = 1e-9;
/// Relative distance (to the bounding-box diagonal) under which two nodes are duplicates.
inline constexpr double mesh_check_duplicate_tolerance = 1e-12;

struct MeshCheckReport {
  int64_t hexes = 0, nodes = 0;
  bool conformal = true;
  int64_t non_conformal_faces = 0;
  int64_t hanging_nodes = 0;
  int64_t inverted_hexes = 0;
  int64_t doublets = 0;
  int64_t nonmanifold_faces = 0;
  int64_t nonmanifold_boundary_edges = 0;
  int64_t duplicate_nodes = 0;
  int64_t unused_nodes = 0;
  int64_t boundary_faces = 0;
  /// Boundary faces touching another part of the boundary with no node between them (without a
  /// reference only; not a defect).
  int64_t self_contact_faces = 0;
  /// Connected components of the hexes under "shares a node" (0 for an empty mesh). Parts that
  /// touch along coincident faces with unmerged nodes (glued or contact interfaces) are several
  /// bodies: a valid mesh, whose interfaces are counted below and are no defect.
  int64_t bodies = 0;
  /// Pairs of boundary faces of two different bodies that touch (every corner of one lies on the
  /// other) with a corner of one at a corner of the other: the coincident faces of a glued
  /// interface, matching face on face or not (a small face on a big one), each pair counted
  /// once; without a reference only (with one, the interface is on the reference's boundary and
  /// is compared there). Such a pair within one body is a gap (non_conformal_faces); a touching
  /// pair of two bodies with no corner on a corner is self-contact.
  int64_t interface_faces = 0;
  /// Nodes within the duplicate tolerance of a lower-id node of another body (both used by hexes)
  /// and of no lower-id node of their own body: for two bodies, the coincident node pairs between
  /// them. Such nodes within one body count as duplicate_nodes instead.
  int64_t interface_nodes = 0;
  /// Over all hexes; 1 for an empty mesh.
  double min_scaled_jacobian = 1.0, mean_scaled_jacobian = 1.0;
  /// Largest hex_edge_ratio over all hexes (longest over shortest edge; 1 for an empty mesh):
  /// what the scaled Jacobian does not see, a hex whose angles are fine and one edge collapsed.
  double max_edge_ratio = 1.0;
  /// Sum of signed hex volumes; sum of boundary-face areas.
  double volume = 0.0, boundary_area = 0.0;
  /// Lowest id of an inverted hex, -1 if none.
  int32_t first_inverted_hex = -1;
  /// The lowest ids (at most mesh_check_defect_hex_limit) of hexes with a defect: inverted, on a
  /// non-conformal or non-manifold face, or in a doublet; ascending.
  std::vector<int32_t> defect_hexes;
  /// Scaled Jacobians in 20 bins of width 0.1 over [-1, 1] (mesh_scaled_jacobian_histogram).
  std::vector<int64_t> scaled_jacobian_histogram;

  /// Reference comparison (meaningful only when reference_compared).
  bool reference_compared = false;
  /// Every boundary quad of the reference is planar (then geometry must be preserved).
  bool reference_planar_faced = false;
  double reference_volume = 0.0, reference_boundary_area = 0.0;
  /// |volume - reference| / |reference| (0 if both are 0); the same for the boundary area.
  double volume_relative_error = 0.0, boundary_area_relative_error = 0.0;
  /// False only if the reference is planar-faced and an error exceeds the tolerance.
  bool geometry_preserved = true;

  /// conformal, no inverted hex, geometry preserved (if compared).
  bool valid() const { return conformal && inverted_hexes == 0 && geometry_preserved; }
};

/// How many defect hexes a report lists.
inline constexpr size_t mesh_check_defect_hex_limit = 20;

class ReferenceSurface;

/// Checks `mesh` (and compares it with `reference`, the mesh before refinement, if given), on up
/// to `threads` threads; the report is the same for every thread count. Throws InputError naming
/// the hex if a node id is out of range or repeated within a hex. `reference_surface`: null, or
/// ReferenceSurface(*reference) built by the caller (refine checks twice against its input and
/// smooths against the same surface: built once).
MeshCheckReport mesh_check(const HexMesh& mesh, const HexMesh* reference = nullptr, int threads = 1,
                           const ReferenceSurface* reference_surface = nullptr);

/// All fields of the report under their own names, plus "valid" (the reference fields only when
/// reference_compared).
void to_json(nlohmann::json& j, const MeshCheckReport& report);

/// Scaled Jacobian histogram: 20 bins of width 0.1 over [-1, 1]; bin b holds values in
/// [-1 + 0.1 b, -1 + 0.1 (b + 1)), the last bin also holds 1.0. Values outside [-1, 1] (and NaN,
/// counted as -1) are clamped into the end bins.
std::vector<int64_t> scaled_jacobian_histogram(const std::vector<double>& values);

/// One line per defect found ("76 inverted hexes, first at id 3"), empty if none.
std::vector<std::string> mesh_check_defects(const MeshCheckReport& report);

}  // namespace hexrefine
