#include "mesh/io.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "mesh/error.hpp"
#include "mesh/hex_convention.hpp"
#include "mesh/hex_face_adjacency.hpp"
#include "mesh/io_text.hpp"

namespace hexrefine {

namespace io_detail {

std::string file_read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open for reading (missing or not readable)");
  // A regular file is read straight into a string of its size (a read that large bypasses the
  // stream's buffer); then whatever follows (a pipe has no size, a file may have grown) is
  // appended in pieces.
  std::string text;
  std::error_code ec;
  const uintmax_t size = std::filesystem::file_size(path, ec);
  if (!ec && size < (uintmax_t{1} << 40)) {
    text.resize(static_cast<size_t>(size));
    in.read(text.data(), static_cast<std::streamsize>(text.size()));
    text.resize(static_cast<size_t>(in.gcount()));
  }
  char piece[1 << 16];
  while (in && (in.read(piece, sizeof piece), in.gcount() > 0))
    text.append(piece, static_cast<size_t>(in.gcount()));
  if (in.bad()) throw InputError(path + ": read failed");
  return text;
}

FileBytes::FileBytes(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  struct stat st {};
  if (fd >= 0 && ::fstat(fd, &st) == 0 && S_ISREG(st.st_mode) && st.st_size > 0) {
    void* p = ::mmap(nullptr, static_cast<size_t>(st.st_size), PROT_READ, MAP_PRIVATE, fd, 0);
    if (p != MAP_FAILED) {
      ::madvise(p, static_cast<size_t>(st.st_size), MADV_SEQUENTIAL);
      map_ = static_cast<const char*>(p);
      size_ = static_cast<size_t>(st.st_size);
    }
  }
  if (fd < 0) {
    copy_ = file_read_all(path);  // names the path: missing or not readable
    return;
  }
  if (S_ISDIR(st.st_mode)) {
    ::close(fd);
    throw InputError(path + ": it is a folder, not a mesh file");
  }
  // Not mapped (a pipe, a special file, an empty file, mmap refused): read from the descriptor
  // already open, since opening a pipe again would wait for another writer.
  bool read_failed = false;
  if (map_ == nullptr) {
    char piece[1 << 16];
    for (;;) {
      const ssize_t n = ::read(fd, piece, sizeof piece);
      if (n > 0) {
        copy_.append(piece, static_cast<size_t>(n));
      } else if (n == 0) {
        break;
      } else if (errno != EINTR) {
        read_failed = true;
        break;
      }
    }
  }
  ::close(fd);
  if (read_failed) throw InputError(path + ": read failed");
}

void FileBytes::release(std::string_view part) const {
  if (map_ == nullptr || part.data() < map_ || part.data() + part.size() > map_ + size_) return;
  const uintptr_t page = static_cast<uintptr_t>(::sysconf(_SC_PAGESIZE));
  const uintptr_t begin = (reinterpret_cast<uintptr_t>(part.data()) + page - 1) / page * page;
  const uintptr_t end = (reinterpret_cast<uintptr_t>(part.data()) + part.size()) / page * page;
  if (end > begin)
    ::madvise(reinterpret_cast<void*>(begin), static_cast<size_t>(end - begin), MADV_DONTNEED);
}

FileBytes::~FileBytes() {
  if (map_ != nullptr) ::munmap(const_cast<char*>(map_), size_);
}

HexBlocks hex_blocks_group(const HexMesh& mesh, int32_t default_id) {
  HexBlocks g;
  const size_t m = mesh.hexes.size();
  g.starts.push_back(0);
  if (m == 0) return g;
  const std::vector<int32_t>* block = mesh_find_attribute(mesh, attribute_block_id);
  g.order.resize(m);
  if (block == nullptr) {
    for (size_t h = 0; h < m; ++h) g.order[h] = static_cast<int32_t>(h);
    g.ids.push_back(default_id);
    g.starts.push_back(m);
    return g;
  }
  const auto [lo, hi] = std::minmax_element(block->begin(), block->end());
  // hi >= lo, so span is in [1, 2^32]; the dense count is taken only up to m + 1024 ids.
  const size_t span = size_t{static_cast<uint32_t>(*hi) - static_cast<uint32_t>(*lo)} + 1;
  if (span <= m + 1024) {
    std::vector<size_t> count(span + 1, 0);
    for (int32_t b : *block) ++count[static_cast<size_t>(int64_t{b} - *lo) + 1];
    for (size_t k = 0; k + 1 < count.size(); ++k)
      if (count[k + 1] > 0) {
        g.ids.push_back(static_cast<int32_t>(*lo + static_cast<int64_t>(k)));
        g.starts.push_back(g.starts.back() + count[k + 1]);
      }
    for (size_t k = 1; k < count.size(); ++k) count[k] += count[k - 1];
    for (size_t h = 0; h < m; ++h)
      g.order[count[static_cast<size_t>(int64_t{(*block)[h]} - *lo)]++] = static_cast<int32_t>(h);
    return g;
  }
  std::vector<std::pair<int32_t, int32_t>> pairs(m);
  for (size_t h = 0; h < m; ++h) pairs[h] = {(*block)[h], static_cast<int32_t>(h)};
  std::sort(pairs.begin(), pairs.end());
  for (size_t i = 0; i < m; ++i) {
    g.order[i] = pairs[i].second;
    if (i == 0 || pairs[i].first != pairs[i - 1].first) {
      if (i > 0) g.starts.push_back(i);
      g.ids.push_back(pairs[i].first);
    }
  }
  g.starts.push_back(m);
  return g;
}

int64_t IdIndex::build(const std::vector<int64_t>& ids) {
  int64_t max_id = 0;
  for (size_t i = 0; i < ids.size(); ++i) {
    if (ids[i] < 1) return static_cast<int64_t>(i);
    max_id = std::max(max_id, ids[i]);
  }
  is_dense_ = max_id <= 4 * static_cast<int64_t>(ids.size()) + 1024;
  if (is_dense_) {
    dense_.assign(static_cast<size_t>(max_id) + 1, -1);
    for (size_t i = 0; i < ids.size(); ++i) {
      int32_t& slot = dense_[static_cast<size_t>(ids[i])];
      if (slot >= 0) return static_cast<int64_t>(i);
      slot = static_cast<int32_t>(i);
    }
    return -1;
  }
  sorted_.resize(ids.size());
  for (size_t i = 0; i < ids.size(); ++i) sorted_[i] = {ids[i], static_cast<int32_t>(i)};
  std::sort(sorted_.begin(), sorted_.end());
  for (size_t i = 1; i < sorted_.size(); ++i)
    if (sorted_[i].first == sorted_[i - 1].first)
      return std::max(sorted_[i].second, sorted_[i - 1].second);
  return -1;
}

int64_t IdIndex::find(int64_t id) const {
  if (is_dense_) {
    if (id < 0 || id >= static_cast<int64_t>(dense_.size())) return -1;
    return dense_[static_cast<size_t>(id)];
  }
  const auto it = std::lower_bound(sorted_.begin(), sorted_.end(), std::make_pair(id, INT32_MIN));
  if (it == sorted_.end() || it->first != id) return -1;
  return it->second;
}

std::vector<int32_t> id_permutation_slots(const std::vector<int64_t>& ids) {
  const int64_t n = static_cast<int64_t>(ids.size());
  if (n > INT32_MAX) return {};
  std::vector<int32_t> slot(ids.size());
  std::vector<char> seen(ids.size(), 0);
  for (int64_t i = 0; i < n; ++i) {
    const int64_t t = ids[i];
    if (t < 1 || t > n || seen[t - 1]) return {};
    seen[t - 1] = 1;
    slot[i] = static_cast<int32_t>(t - 1);
  }
  return slot;
}

void mesh_check_read(const HexMesh& mesh, const std::string& path, bool manifold_test) {
  mesh_validate_ids(mesh, path);
  if (manifold_test) mesh_require_manifold(mesh, path);
}

}  // namespace io_detail

void mesh_require_manifold(const HexMesh& mesh, const std::string& path) {
  // Only the non-manifold faces are wanted: no neighbour array (a third of the peak memory of
  // reading an 11 M-hex mesh).
  const HexFaceAdjacency adjacency = hex_face_adjacency_build(mesh, 1, false);
  if (!adjacency.nonmanifold_faces.empty()) {
    const HexFaceSlot& slot = adjacency.nonmanifold_faces[0];
    const HexCell& c = mesh.hexes[slot.hex];
    const int* fv = hex_faces[slot.local_face];
    throw InputError(path + ": non-manifold mesh: face with nodes " + std::to_string(c[fv[0]]) +
                     " " + std::to_string(c[fv[1]]) + " " + std::to_string(c[fv[2]]) + " " +
                     std::to_string(c[fv[3]]) + " (0-based) is shared by more than two hexes (" +
                     std::to_string(adjacency.nonmanifold_faces.size()) + " such faces)");
  }
}

namespace {

std::string extension_of(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  const size_t dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string ext = path.substr(dot);
  for (char& c : ext) c = io_detail::TextCursor::lower(c);
  return ext;
}

/// Names travel inside VTK headers (no white space), XML attributes and Gmsh strings (no quotes
/// or markup characters): printable ASCII without ' " < > &, at most 128 characters.
void name_check(const std::string& path, const std::string& name) {
  bool ok = !name.empty() && name.size() <= 128;
  for (char c : name)
    if (c <= ' ' || c > '~' || c == '"' || c == '\'' || c == '<' || c == '>' || c == '&')
      ok = false;
  if (!ok)
    throw InputError(path + ": cannot write field name '" + name +
                     "': use 1-128 printable characters without white space, quotes, <, > or &");
}

}  // namespace

MeshFormat mesh_format_of(const std::string& path) {
  const std::string ext = extension_of(path);
  if (ext == ".mesh") return MeshFormat::medit;
  if (ext == ".vtk") return MeshFormat::vtk_legacy;
  if (ext == ".vtu") return MeshFormat::vtu;
  if (ext == ".msh") return MeshFormat::gmsh;
  if (ext == ".e" || ext == ".exo") return MeshFormat::exodus;
  if (ext == ".inp") return MeshFormat::abaqus;
  throw InputError(path +
                   ": unknown mesh format (expected extension .mesh, .vtk, .vtu, .msh, .e, .exo "
                   "or .inp)");
}

namespace {

HexMesh mesh_read_format(const std::string& path, MeshFormat format) {
  switch (format) {
    case MeshFormat::medit:
      return io_detail::medit_read(path, io_detail::FileBytes(path).view());
    case MeshFormat::vtk_legacy: {
      const io_detail::FileBytes file(path);
      return io_detail::vtk_read(path, file.view(), &file);
    }
    case MeshFormat::vtu: {
      const io_detail::FileBytes file(path);
      return io_detail::vtu_read(path, file.view(), &file);
    }
    case MeshFormat::gmsh: {
      const io_detail::FileBytes file(path);
      return io_detail::gmsh_read(path, file.view(), &file);
    }
    case MeshFormat::exodus:
      return io_detail::exodus_read(path);
    case MeshFormat::abaqus:
      return io_detail::abaqus_read(path, io_detail::FileBytes(path).view());
  }
  throw InputError(path + ": unknown mesh format");
}

}  // namespace

HexMesh mesh_read(const std::string& path, const MeshReadOptions& options) {
  const MeshFormat format = mesh_format_of(path);
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw InputError(path + ": is a folder, expected a mesh file");
  // The checks run once the reader has returned and freed what it held (peak memory).
  HexMesh mesh = mesh_read_format(path, format);
  io_detail::mesh_check_read(mesh, path, options.manifold_test);
  return mesh;
}

HexMesh mesh_read_from_memory(const std::string& name, std::string_view bytes) {
  const MeshFormat format = mesh_format_of(name);
  if (format == MeshFormat::exodus) {
    // libexodusii opens files by name only; mkstemps gives a fresh private file.
    std::string tmp =
        (std::filesystem::temp_directory_path() / "hexrefine_memory_XXXXXX.e").string();
    const int fd = ::mkstemps(tmp.data(), 2);
    if (fd < 0) throw OperationError(name + ": cannot create a temporary file to read Exodus II");
    ::close(fd);
    struct Remove {
      std::string path;
      ~Remove() { std::remove(path.c_str()); }
    } remove_tmp{tmp};
    {
      std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
      out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
      if (!out) throw OperationError(name + ": cannot write a temporary file to read Exodus II");
    }
    try {
      HexMesh mesh = io_detail::exodus_read(tmp);
      io_detail::mesh_check_read(mesh, tmp, true);
      return mesh;
    } catch (const InputError& e) {
      // Name the caller's source, not the temporary file.
      std::string message = e.what();
      if (message.rfind(tmp, 0) == 0) message = name + message.substr(tmp.size());
      throw InputError(message);
    }
  }
  const std::string_view text = bytes;
  HexMesh mesh;
  switch (format) {
    case MeshFormat::medit:
      mesh = io_detail::medit_read(name, text);
      break;
    case MeshFormat::vtk_legacy:
      mesh = io_detail::vtk_read(name, text);
      break;
    case MeshFormat::vtu:
      mesh = io_detail::vtu_read(name, text);
      break;
    case MeshFormat::gmsh:
      mesh = io_detail::gmsh_read(name, text);
      break;
    case MeshFormat::abaqus:
      mesh = io_detail::abaqus_read(name, text);
      break;
    case MeshFormat::exodus:
      throw InputError(name + ": unknown mesh format");
  }
  io_detail::mesh_check_read(mesh, name, true);
  return mesh;
}

MeshFormatHolds mesh_format_holds(MeshFormat format) {
  // What each writer writes today; a writer that learns to write more updates its row.
  switch (format) {
    case MeshFormat::medit:
      return {};
    case MeshFormat::vtk_legacy:
    case MeshFormat::vtu:
      return {};
    case MeshFormat::gmsh:
      return {};
    case MeshFormat::exodus:
      return {};
    case MeshFormat::abaqus:
      return {};
  }
  return {};
}

std::vector<std::string> mesh_format_drops(const HexMesh& mesh, MeshFormat format) {
  const MeshFormatHolds holds = mesh_format_holds(format);
  std::vector<std::string> dropped;
  if (!holds.block_names)
    for (const BlockName& b : mesh.block_names)
      dropped.push_back("name '" + b.name + "' of block " + std::to_string(b.id));
  if (!holds.side_sets)
    for (const SideSet& s : mesh.side_sets) dropped.push_back(side_set_label(s));
  for (const NodeSet& s : mesh.node_sets) {
    if (!holds.node_sets)
      dropped.push_back(node_set_label(s));
    else if (!holds.node_set_distribution_factors && !s.distribution_factors.empty())
      dropped.push_back("distribution factors of " + node_set_label(s));
  }
  for (const MeshField& f : mesh.fields) {
    const bool on_nodes = f.location == FieldLocation::node;
    if (on_nodes ? !holds.node_fields : !holds.hex_fields)
      dropped.push_back(std::string(on_nodes ? "nodal" : "element") + " field '" + f.name + "'");
  }
  if (!holds.title && !mesh.title.empty()) dropped.push_back("title '" + mesh.title + "'");
  return dropped;
}

std::vector<std::string> mesh_write(const std::string& path, const HexMesh& mesh,
                                    const MeshWriteOptions& options) {
  const MeshFormat format = mesh_format_of(path);
  mesh_validate_ids(mesh, "mesh to write to " + path);
  for (size_t i = 0; i < mesh.points.size(); ++i)
    if (!mesh.points[i].allFinite())
      throw InputError(path + ": cannot write node " + std::to_string(i) +
                       ": coordinate is NaN or infinite");
  for (const HexAttribute& a : mesh.attributes) name_check(path, a.name);
  for (const auto& [name, values] : options.cell_scalars) {
    name_check(path, name);
    if (values.size() != mesh.hexes.size())
      throw InputError(path + ": cell field '" + name + "' has " + std::to_string(values.size()) +
                       " values for " + std::to_string(mesh.hexes.size()) + " hexes");
  }
  switch (format) {
    case MeshFormat::medit:
      io_detail::medit_write(path, mesh);
      break;
    case MeshFormat::vtk_legacy:
      io_detail::vtk_write(path, mesh, options.binary, options.cell_scalars);
      break;
    case MeshFormat::vtu:
      io_detail::vtu_write(path, mesh, options.cell_scalars, options.ascii, options.compress);
      break;
    case MeshFormat::gmsh:
      io_detail::gmsh_write(path, mesh, options.binary, options.cell_scalars);
      break;
    case MeshFormat::exodus:
      io_detail::exodus_write(path, mesh, options.cell_scalars);
      break;
    case MeshFormat::abaqus:
      io_detail::abaqus_write(path, mesh);
      break;
  }
  return mesh_format_drops(mesh, format);
}

}  // namespace hexrefine
