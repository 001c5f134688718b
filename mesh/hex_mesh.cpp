#include "mesh/hex_mesh.hpp"

#include "mesh/error.hpp"
#include "mesh/parallel.hpp"

namespace hexrefine {

std::string error_at(const std::string& file, int64_t line, const std::string& message) {
  if (line <= 0) return file + ": " + message;
  return file + ":" + std::to_string(line) + ": " + message;
}

const std::vector<int32_t>* mesh_find_attribute(const HexMesh& mesh, std::string_view name) {
  for (const HexAttribute& a : mesh.attributes)
    if (a.name == name) return &a.values;
  return nullptr;
}

std::vector<int32_t>& mesh_attribute(HexMesh& mesh, std::string_view name, int32_t fill) {
  for (HexAttribute& a : mesh.attributes)
    if (a.name == name) {
      a.values.resize(mesh.hexes.size(), fill);
      return a.values;
    }
  mesh.attributes.push_back({std::string(name), std::vector<int32_t>(mesh.hexes.size(), fill)});
  return mesh.attributes.back().values;
}

std::string_view mesh_block_name(const HexMesh& mesh, int32_t id) {
  for (const BlockName& b : mesh.block_names)
    if (b.id == id) return b.name;
  return {};
}

const MeshField* mesh_find_field(const HexMesh& mesh, std::string_view name,
                                 FieldLocation location) {
  for (const MeshField& f : mesh.fields)
    if (f.name == name && f.location == location) return &f;
  return nullptr;
}

namespace {
std::string set_label(const char* kind, int64_t id, const std::string& name) {
  std::string s = std::string(kind) + " " + std::to_string(id);
  if (!name.empty()) s += " '" + name + "'";
  return s;
}

/// Throws InputError for the first inconsistent side set, node set or field of `mesh`.
void mesh_validate_annotations(const HexMesh& mesh, const std::string& what) {
  const int64_t hexes = mesh.hex_count(), nodes = mesh.point_count();
  for (const SideSet& s : mesh.side_sets) {
    if (s.hexes.size() != s.faces.size())
      throw InputError(what + ": " + side_set_label(s) + " has " + std::to_string(s.hexes.size()) +
                       " hexes for " + std::to_string(s.faces.size()) + " faces");
    for (size_t k = 0; k < s.hexes.size(); ++k) {
      if (s.hexes[k] < 0 || s.hexes[k] >= hexes)
        throw InputError(what + ": " + side_set_label(s) + ": entry " + std::to_string(k) +
                         " names hex " + std::to_string(s.hexes[k]) + ", expected 0.." +
                         std::to_string(hexes - 1));
      if (s.faces[k] < 0 || s.faces[k] > 5)
        throw InputError(what + ": " + side_set_label(s) + ": entry " + std::to_string(k) +
                         " names face " + std::to_string(s.faces[k]) + " of hex " +
                         std::to_string(s.hexes[k]) + ", expected 0..5");
    }
  }
  for (const NodeSet& s : mesh.node_sets) {
    for (size_t k = 0; k < s.nodes.size(); ++k)
      if (s.nodes[k] < 0 || s.nodes[k] >= nodes)
        throw InputError(what + ": " + node_set_label(s) + ": entry " + std::to_string(k) +
                         " names node " + std::to_string(s.nodes[k]) + ", expected 0.." +
                         std::to_string(nodes - 1));
    if (!s.distribution_factors.empty() && s.distribution_factors.size() != s.nodes.size())
      throw InputError(what + ": " + node_set_label(s) + " has " +
                       std::to_string(s.distribution_factors.size()) +
                       " distribution factors for " + std::to_string(s.nodes.size()) + " nodes");
  }
  for (const MeshField& f : mesh.fields) {
    const bool on_nodes = f.location == FieldLocation::node;
    const int64_t count = on_nodes ? nodes : hexes;
    if (f.components < 1 ||
        static_cast<int64_t>(f.values.size()) != count * static_cast<int64_t>(f.components))
      throw InputError(what + ": " + (on_nodes ? "nodal" : "element") + " field '" + f.name +
                       "' has " + std::to_string(f.values.size()) + " values, expected " +
                       std::to_string(count) + " " + (on_nodes ? "nodes" : "hexes") + " x " +
                       std::to_string(f.components) + " components");
  }
}
}  // namespace

std::string side_set_label(const SideSet& set) {
  return set_label("side set", set.id, set.name);
}
std::string node_set_label(const NodeSet& set) {
  return set_label("node set", set.id, set.name);
}

bool mesh_has_annotations(const HexMesh& mesh) {
  return !mesh.block_names.empty() || !mesh.side_sets.empty() || !mesh.node_sets.empty() ||
         !mesh.fields.empty() || !mesh.title.empty();
}

void mesh_validate_ids(const HexMesh& mesh, const std::string& what, int threads) {
  const int64_t n = static_cast<int64_t>(mesh.points.size());
  // Per chunk of hexes; the first chunk's error is the one rethrown, so the message names the
  // lowest offending hex for any thread count.
  parallel_chunks(threads, mesh.hex_count(), 1 << 16, [&](int64_t, int64_t begin, int64_t end) {
    for (int64_t h = begin; h < end; ++h) {
      const HexCell& c = mesh.hexes[h];
      // Branch-free test first (the range and the 28 pairs or-ed, which the compiler vectorises);
      // the loop below only names the defect.
      bool bad = false;
      for (int i = 0; i < 8; ++i) {
        bad |= (c[i] < 0) | (c[i] >= n);
        for (int j = 0; j < i; ++j) bad |= c[j] == c[i];
      }
      if (!bad) continue;
      for (int i = 0; i < 8; ++i) {
        if (c[i] < 0 || c[i] >= n)
          throw InputError(what + ": hex " + std::to_string(h) + " refers to node " +
                           std::to_string(c[i]) + ", expected 0.." + std::to_string(n - 1));
        for (int j = 0; j < i; ++j)
          if (c[j] == c[i])
            throw InputError(what + ": hex " + std::to_string(h) + " repeats node " +
                             std::to_string(c[i]) + " (degenerate hex)");
      }
    }
  });
  for (const HexAttribute& a : mesh.attributes)
    if (a.values.size() != mesh.hexes.size())
      throw InputError(what + ": attribute '" + a.name + "' has " +
                       std::to_string(a.values.size()) + " values for " +
                       std::to_string(mesh.hexes.size()) + " hexes");
  mesh_validate_annotations(mesh, what);
}

Eigen::Vector3d hex_centroid(const HexMesh& mesh, int32_t h) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (int32_t v : mesh.hexes[h]) c += mesh.points[v];
  return c / 8.0;
}

std::array<Eigen::Vector3d, 8> hex_points(const HexMesh& mesh, int32_t h) {
  std::array<Eigen::Vector3d, 8> p;
  for (int i = 0; i < 8; ++i) p[i] = mesh.points[mesh.hexes[h][i]];
  return p;
}

std::pair<Eigen::Vector3d, Eigen::Vector3d> mesh_bounding_box(const HexMesh& mesh) {
  if (mesh.points.empty()) return {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  Eigen::Vector3d lo = mesh.points[0], hi = mesh.points[0];
  for (const Eigen::Vector3d& p : mesh.points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  return {lo, hi};
}

SubMesh mesh_extract(const HexMesh& mesh, const std::vector<int32_t>& hexes) {
  SubMesh sub;
  std::vector<int32_t> local(mesh.points.size(), -1);
  sub.mesh.hexes.reserve(hexes.size());
  for (int32_t h : hexes) {
    HexCell c = mesh.hexes[h];
    for (int32_t& v : c) {
      if (local[v] < 0) {
        local[v] = static_cast<int32_t>(sub.node_of.size());
        sub.node_of.push_back(v);
      }
      v = local[v];
    }
    sub.mesh.hexes.push_back(c);
  }
  sub.mesh.points.reserve(sub.node_of.size());
  for (int32_t v : sub.node_of) sub.mesh.points.push_back(mesh.points[v]);
  return sub;
}

}  // namespace hexrefine
