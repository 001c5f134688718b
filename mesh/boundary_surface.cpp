/// Boundary surface as an OpenMesh PolyMesh and its feature-angle patches.
///
/// Steps: (1) every boundary face (face_hexes[f][1] < 0) is added as an OpenMesh quad, its nodes
/// mapped to OpenMesh vertices on first use; a face OpenMesh refuses (complex edge or vertex) is
/// added again on fresh copies of its vertices so the surface stays a valid half-edge structure;
/// (2) patches: breadth-first flood fill across half-edge pairs whose face normals differ by less
/// than the feature angle.
#include "mesh/boundary_surface.hpp"

#include <Eigen/Geometry>
#include <OpenMesh/Core/System/omstream.hh>
#include <cmath>
#include <numbers>

#include "mesh/hex_convention.hpp"

namespace hexrefine {

Eigen::Vector3d quad_area_normal(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                 const Eigen::Vector3d& c, const Eigen::Vector3d& d) {
  return (c - a).cross(d - b);
}

Eigen::Vector3d face_unit_normal(const HexMesh& mesh, const HexTopology& t, int32_t face) {
  const auto& q = t.face_nodes[face];
  const Eigen::Vector3d n =
      quad_area_normal(mesh.points[q[0]], mesh.points[q[1]], mesh.points[q[2]], mesh.points[q[3]]);
  const double len = n.norm();
  return len > 0 ? Eigen::Vector3d(n / len) : Eigen::Vector3d::Zero();
}

BoundarySurface boundary_surface_build(const HexMesh& mesh, const HexTopology& t) {
  BoundarySurface s;
  std::vector<int32_t> node_vertex(t.node_count, -1);
  auto add_vertex = [&](int32_t node) {
    const Eigen::Vector3d& p = mesh.points[node];
    const SurfaceMesh::VertexHandle v =
        s.surface.add_vertex(SurfaceMesh::Point(p.x(), p.y(), p.z()));
    s.vertex_node.push_back(node);
    return v;
  };
  // OpenMesh reports refused faces on omerr; the refusal is handled here, so keep it quiet.
  const bool omerr_was_enabled = ::omerr().is_enabled();
  ::omerr().disable();
  std::vector<SurfaceMesh::VertexHandle> quad(4);
  for (int32_t f = 0; f < t.face_count(); ++f) {
    if (!face_is_boundary(t, f)) continue;
    const int32_t h = t.face_hexes[f][0];
    const int lf = hex_local_face(t, h, f);  // faces-only topologies have no face_local
    for (int i = 0; i < 4; ++i) {
      const int32_t node = mesh.hexes[h][hex_faces[lf][i]];
      if (node_vertex[node] < 0) node_vertex[node] = add_vertex(node).idx();
      quad[i] = SurfaceMesh::VertexHandle(node_vertex[node]);
    }
    SurfaceMesh::FaceHandle fh = s.surface.add_face(quad);
    if (!fh.is_valid()) {
      for (int i = 0; i < 4; ++i) quad[i] = add_vertex(s.vertex_node[quad[i].idx()]);
      fh = s.surface.add_face(quad);
      ++s.split_face_count;
    }
    s.face_hex.push_back(h);
    s.face_local.push_back(static_cast<int8_t>(lf));
    s.face_id.push_back(f);
  }
  if (omerr_was_enabled) ::omerr().enable();
  return s;
}

SurfacePatches boundary_surface_patches(const BoundarySurface& s, double feature_angle_degrees) {
  const SurfaceMesh& m = s.surface;
  const int32_t nf = static_cast<int32_t>(m.n_faces());
  std::vector<Eigen::Vector3d> normal(nf);
  for (int32_t i = 0; i < nf; ++i) {
    std::array<Eigen::Vector3d, 4> p;
    int k = 0;
    for (SurfaceMesh::VertexHandle v : m.fv_range(SurfaceMesh::FaceHandle(i))) {
      const auto& q = m.point(v);
      if (k < 4) p[k] = Eigen::Vector3d(q[0], q[1], q[2]);
      ++k;
    }
    const Eigen::Vector3d n = quad_area_normal(p[0], p[1], p[2], p[3]);
    normal[i] = n.norm() > 0 ? Eigen::Vector3d(n.normalized()) : Eigen::Vector3d::Zero();
  }
  const double cos_feature = std::cos(feature_angle_degrees * std::numbers::pi / 180.0);

  SurfacePatches out;
  out.face_patch.assign(nf, -1);
  std::vector<int32_t> queue;
  queue.reserve(nf);
  for (int32_t seed = 0; seed < nf; ++seed) {
    if (out.face_patch[seed] >= 0) continue;
    const int32_t patch = out.patch_count();
    out.patch_face_counts.push_back(0);
    queue.clear();
    queue.push_back(seed);
    out.face_patch[seed] = patch;
    for (size_t head = 0; head < queue.size(); ++head) {
      const int32_t f = queue[head];
      ++out.patch_face_counts[patch];
      // A zero normal has dot 0 with everything, so a degenerate face stays alone for any
      // feature angle below 90 degrees; make that hold for all angles.
      if (normal[f].isZero()) continue;
      for (SurfaceMesh::HalfedgeHandle he : m.fh_range(SurfaceMesh::FaceHandle(f))) {
        const SurfaceMesh::FaceHandle g = m.opposite_face_handle(he);
        if (!g.is_valid() || out.face_patch[g.idx()] >= 0 || normal[g.idx()].isZero()) continue;
        if (normal[f].dot(normal[g.idx()]) <= cos_feature) continue;
        out.face_patch[g.idx()] = patch;
        queue.push_back(g.idx());
      }
    }
  }
  return out;
}

}  // namespace hexrefine
