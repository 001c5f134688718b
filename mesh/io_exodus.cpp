/// \file
/// Exodus II (.e, .exo) through libexodusii. HEX8 (and HEX/HEXAHEDRON with 8 nodes) has VTK's
/// node order. Each element block is one block_id; blocks of other 3D elements (TETRA, WEDGE,
/// PYRAMID, HEX20, HEX27, NFACED) are refused, blocks of shells, quads, triangles, bars and spheres
/// are skipped. Exodus block ids must be positive: a block_id <= 0 is written under a fresh
/// positive id (above every positive block_id) and the block is named "hexrefine_block_id=<v>";
/// the reader takes block_id from such a name, else from the Exodus id. Coordinates are written as
/// doubles (exact round trip). Hexes are written block by block with the element id map holding
/// each hex's index + 1; the reader orders hexes by id when the ids of the hexes are a permutation
/// of 1..n, so a written mesh reads back in its own order. The library writes the definitions and
/// the small variables; the bulk arrays (coordinates, connectivity, id map, element variables)
/// are written afterwards at the offsets of the classic netCDF header it wrote.

#include <exodusII.h>
#include <netcdf.h>

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include "mesh/atomic_file.hpp"
#include "mesh/io.hpp"
#include "mesh/io_exodus_guard.hpp"
#include "mesh/io_text.hpp"

namespace hexrefine::io_detail {

namespace {

/// Entries per chunk of the bulk arrays (coordinates, connectivity, maps, variables) in both
/// directions: buffers of a few tens of MB, reused, instead of whole-mesh copies.
constexpr size_t exodus_chunk = size_t{1} << 20;

/// Closes the Exodus file on every path out.
struct ExodusFile {
  int id = -1;
  ~ExodusFile() {
    if (id >= 0) ex_close(id);
  }
};

std::string upper(const char* s) {
  std::string u(s);
  for (char& c : u)
    if (c >= 'a' && c <= 'z') c = static_cast<char>(c - 32);
  return u;
}

}  // namespace

/// The element variables of the hex blocks whose values are all integers (in the int32 range) at
/// the first time step, as attributes in the reader's hex order (blocks in file order), read
/// through netCDF with every shape checked (name_elem_var: num_elem_var x len_name; vals_elem_var
/// VebB: time_step x num_el_in_blkB) rather than through libexodusii (see exodus_netcdf_check).
/// A variable missing from a hex block, or with a non-integral value, is skipped; block_id is
/// skipped (it comes from the blocks).
std::vector<HexAttribute> exodus_element_variables(
    const std::string& path, const std::vector<std::pair<int64_t, int64_t>>& hex_blocks) {
  std::vector<HexAttribute> out;
  NetcdfFile file;
  if (nc_open(path.c_str(), NC_NOWRITE, &file.id) != NC_NOERR) {
    file.id = -1;
    return out;
  }
  auto dimension = [&](const std::string& name) -> int64_t {
    int id = -1;
    size_t length = 0;
    if (nc_inq_dimid(file.id, name.c_str(), &id) != NC_NOERR ||
        nc_inq_dimlen(file.id, id, &length) != NC_NOERR)
      return -1;
    return static_cast<int64_t>(length);
  };
  // The variable `name` of rank 2 over exactly (d0, d1), its id or -1.
  auto variable = [&](const std::string& name, const std::string& d0, const std::string& d1) {
    int id = -1, rank = 0, dims[NC_MAX_VAR_DIMS] = {0};
    char dim_name[NC_MAX_NAME + 1] = {0};
    if (nc_inq_varid(file.id, name.c_str(), &id) != NC_NOERR ||
        nc_inq_varndims(file.id, id, &rank) != NC_NOERR || rank != 2 ||
        nc_inq_vardimid(file.id, id, dims) != NC_NOERR)
      return -1;
    for (int d = 0; d < 2; ++d)
      if (nc_inq_dimname(file.id, dims[d], dim_name) != NC_NOERR || dim_name != (d ? d1 : d0))
        return -1;
    return id;
  };
  const int64_t count = dimension("num_elem_var"), name_length = dimension("len_name");
  if (count <= 0 || count > 1000 || name_length <= 0 || name_length > 4096 ||
      dimension("time_step") < 1)
    return out;
  const int names_id = variable("name_elem_var", "num_elem_var", "len_name");
  if (names_id < 0) return out;
  std::vector<char> names(static_cast<size_t>(count * name_length) + 1, 0);
  nc_type names_type = NC_NAT;
  if (nc_inq_vartype(file.id, names_id, &names_type) != NC_NOERR || names_type != NC_CHAR)
    return out;
  if (nc_get_var_text(file.id, names_id, names.data()) != NC_NOERR)
    throw InputError(path + ": cannot read the element variable names: corrupt or truncated file");
  int64_t total = 0;
  for (const auto& [b, n] : hex_blocks) total += n;
  for (int64_t v = 0; v < count; ++v) {
    const char* begin = names.data() + v * name_length;
    std::string name(begin, strnlen(begin, static_cast<size_t>(name_length)));
    while (!name.empty() && name.back() == ' ') name.pop_back();
    if (name.empty() || name == attribute_block_id) continue;
    HexAttribute a{name, {}};
    a.values.reserve(total);
    bool ok = true;
    std::vector<double> values;
    for (const auto& [b, n] : hex_blocks) {
      const std::string k = std::to_string(b + 1);
      const int id = variable("vals_elem_var" + std::to_string(v + 1) + "eb" + k, "time_step",
                              "num_el_in_blk" + k);
      if (id < 0 || dimension("num_el_in_blk" + k) != n) {
        ok = false;
        break;
      }
      // In chunks: a block's doubles would be twice the attribute's own int32 array.
      for (int64_t first = 0; first < n && ok; first += static_cast<int64_t>(exodus_chunk)) {
        const int64_t chunk = std::min<int64_t>(n - first, exodus_chunk);
        values.resize(static_cast<size_t>(chunk));
        const size_t start[2] = {0, static_cast<size_t>(first)},
                     extent[2] = {1, static_cast<size_t>(chunk)};
        if (nc_get_vara_double(file.id, id, start, extent, values.data()) != NC_NOERR)
          throw InputError(path + ": cannot read element variable '" + name + "' of block " + k +
                           ": corrupt or truncated file");
        for (double x : values) {
          // netCDF returns its fill value for data missing from a truncated file.
          if (x == 9.9692099683868690e+36)
            throw InputError(path + ": element variable '" + name + "' of block " + k +
                             " has an unwritten (netCDF fill) value: corrupt or truncated file");
          if (!(x == std::floor(x) && x >= INT32_MIN && x <= INT32_MAX)) {
            ok = false;
            break;
          }
          a.values.push_back(static_cast<int32_t>(x));
        }
      }
      if (!ok) break;
    }
    if (ok) out.push_back(std::move(a));
  }
  return out;
}

HexMesh exodus_read(const std::string& path) {
  // Check the netCDF signature ourselves first: the library must only ever see files that at
  // least claim to be netCDF, and the size bounds the counts below.
  int64_t file_size = 0;
  bool hdf5 = false;
  {
    std::ifstream f(path, std::ios::binary | std::ios::ate);
    if (!f) throw InputError(path + ": cannot open for reading (missing or not readable)");
    file_size = static_cast<int64_t>(f.tellg());
    char magic[4] = {0, 0, 0, 0};
    f.seekg(0);
    f.read(magic, 4);
    const bool classic = magic[0] == 'C' && magic[1] == 'D' && magic[2] == 'F' &&
                         (magic[3] == 1 || magic[3] == 2 || magic[3] == 5);
    hdf5 = magic[0] == '\x89' && magic[1] == 'H' && magic[2] == 'D' && magic[3] == 'F';
    if (!f || (!classic && !hdf5))
      throw InputError(path +
                       ": not an Exodus II file (expected a netCDF 'CDF' or HDF5 signature)");
    if (classic) {
      // The header is usually a few KB: check it from the first 1 MB, or the whole file if it
      // is longer.
      for (int64_t read = std::min<int64_t>(file_size, 1 << 20);; read = file_size) {
        std::string head(static_cast<size_t>(read), '\0');
        f.seekg(0);
        f.read(head.data(), read);
        if (!f) throw InputError(path + ": read failed");
        if (netcdf_classic_header_check(path, head, file_size) || read == file_size) break;
      }
    }
  }
  exodus_netcdf_check(path);
  ex_opts(EX_DEFAULT);  // report errors through return codes only; never abort
  int comp_ws = 8, io_ws = 0;
  float version = 0;
  ExodusFile file;
  file.id = ex_open(path.c_str(), EX_READ | EX_ALL_INT64_API, &comp_ws, &io_ws, &version);
  if (file.id < 0)
    throw InputError(path + ": cannot open as Exodus II (corrupt or truncated netCDF)");
  char title[MAX_LINE_LENGTH + 1] = {0};
  int64_t dim = 0, nodes = 0, elems = 0, blocks = 0, node_sets = 0, side_sets = 0;
  if (ex_get_init(file.id, title, &dim, &nodes, &elems, &blocks, &node_sets, &side_sets) < 0)
    throw InputError(path + ": cannot read the Exodus II header");
  if (dim != 3)
    throw InputError(path + ": Exodus II dimension " + std::to_string(dim) + ", expected 3");
  // Classic files store every value: 4 bytes per coordinate and per connectivity entry at least.
  // HDF5 files may be compressed, so they get a generous factor.
  const int64_t budget = hdf5 ? file_size * 1000 : file_size;
  if (nodes < 0 || elems < 0 || blocks < 0 || nodes > INT32_MAX || elems > INT32_MAX ||
      nodes > budget / 12 || elems > budget / 4 || blocks > elems + 1)
    throw InputError(path + ": Exodus II header claims " + std::to_string(nodes) + " nodes, " +
                     std::to_string(elems) + " elements, " + std::to_string(blocks) +
                     " blocks: more than the file (" + std::to_string(file_size) +
                     " bytes) can hold");
  HexMesh mesh;
  {
    std::vector<double> x, y, z;
    mesh.points.resize(nodes);
    for (int64_t begin = 0; begin < nodes; begin += static_cast<int64_t>(exodus_chunk)) {
      const int64_t count = std::min<int64_t>(nodes - begin, exodus_chunk);
      x.resize(count), y.resize(count), z.resize(count);
      if (ex_get_partial_coord(file.id, begin + 1, count, x.data(), y.data(), z.data()) < 0)
        throw InputError(path + ": cannot read the node coordinates");
      for (int64_t k = 0; k < count; ++k) {
        const int64_t i = begin + k;
        mesh.points[i] = Eigen::Vector3d(x[k], y[k], z[k]);
        // netCDF returns its fill value for data missing from a truncated file.
        if (!mesh.points[i].allFinite() || (mesh.points[i].array() == 9.9692099683868690e+36).any())
          throw InputError(path + ": node " + std::to_string(i + 1) +
                           " has a NaN, infinite or unwritten (netCDF fill) coordinate: corrupt "
                           "or truncated file");
      }
    }
  }
  std::vector<int64_t> block_ids(blocks);
  if (blocks > 0 && ex_get_ids(file.id, EX_ELEM_BLOCK, block_ids.data()) < 0)
    throw InputError(path + ": cannot read the element block ids");
  std::vector<int64_t> element_map(elems);
  if (elems > 0 && ex_get_id_map(file.id, EX_ELEM_MAP, element_map.data()) < 0)
    throw InputError(path + ": cannot read the element id map");
  for (int64_t e = 0; e < elems; ++e)
    if (element_map[e] < 1)
      throw InputError(path + ": element " + std::to_string(e + 1) + " has id " +
                       std::to_string(element_map[e]) +
                       " in the element id map, expected >= 1 "
                       "(corrupt or truncated file)");
  std::vector<int32_t> block;
  mesh.hexes.reserve(elems);
  block.reserve(elems);
  // First element (0-based, file order) of each hex block, beside hex_blocks.
  std::vector<int64_t> hex_block_first;
  std::vector<std::pair<int64_t, int64_t>> hex_blocks;  // (file-order block index, hex count)
  int64_t first_element = 0;
  for (int64_t b = 0; b < blocks; ++b) {
    const int64_t bid = block_ids[b];
    const std::string where = path + ": element block " + std::to_string(bid);
    char type_name[MAX_STR_LENGTH + 1] = {0};
    int64_t count = 0, per = 0, edges = 0, faces = 0, attrs = 0;
    if (ex_get_block(file.id, EX_ELEM_BLOCK, bid, type_name, &count, &per, &edges, &faces, &attrs) <
        0)
      throw InputError(where + ": cannot read its parameters");
    if (count < 0 || per < 0 || count > elems - first_element || per > 1000)
      throw InputError(where + ": bad element count " + std::to_string(count) +
                       " or nodes per element " + std::to_string(per));
    const std::string type = upper(type_name);
    const bool hex = type.rfind("HEX", 0) == 0 && per == 8;
    const bool volume = type.rfind("HEX", 0) == 0 || type.rfind("TET", 0) == 0 ||
                        type.rfind("WEDGE", 0) == 0 || type.rfind("PYRAMID", 0) == 0 ||
                        type.rfind("NFACED", 0) == 0 || type.rfind("POLYHED", 0) == 0;
    if (volume && !hex)
      throw InputError(where + " has " + std::to_string(count) + " elements of type " + type +
                       " with " + std::to_string(per) +
                       " nodes: only linear hexahedra (HEX8) are supported");
    if (hex && count > 0) {
      int64_t block_id = bid;
      char block_name[257] = {0};  // beyond any name length the library returns
      if (ex_get_name(file.id, EX_ELEM_BLOCK, bid, block_name) >= 0) {
        const std::string_view name(block_name);
        const std::string_view prefix = "hexrefine_block_id=";
        int64_t v = 0;
        if (name.substr(0, prefix.size()) == prefix &&
            TextCursor::parse_integer(name.substr(prefix.size()), v))
          block_id = v;
      }
      if (block_id < INT32_MIN || block_id > INT32_MAX)
        throw InputError(where + ": block id out of the int32 range");
      std::vector<int64_t> conn;
      for (int64_t begin = 0; begin < count; begin += static_cast<int64_t>(exodus_chunk)) {
        const int64_t chunk = std::min<int64_t>(count - begin, exodus_chunk);
        conn.resize(chunk * 8);
        if (ex_get_partial_conn(file.id, EX_ELEM_BLOCK, bid, begin + 1, chunk, conn.data(), nullptr,
                                nullptr) < 0)
          throw InputError(where + ": cannot read its connectivity");
        for (int64_t e = 0; e < chunk; ++e) {
          HexCell c;
          for (int k = 0; k < 8; ++k) {
            const int64_t v = conn[e * 8 + k];
            if (v < 1 || v > nodes)
              throw InputError(where + ", element " + std::to_string(begin + e + 1) + ": node " +
                               std::to_string(v) + " out of range 1.." + std::to_string(nodes));
            c[k] = static_cast<int32_t>(v - 1);
          }
          mesh.hexes.push_back(c);
          block.push_back(static_cast<int32_t>(block_id));
        }
      }
      hex_blocks.push_back({b, count});
      hex_block_first.push_back(first_element);
    }
    first_element += count;
  }
  // Restore the written order when the hex ids are exactly 1..m. The element map and the
  // bookkeeping are released before the element variables are read (peak memory).
  const size_t m = mesh.hexes.size();
  std::vector<int32_t> slot(m);
  bool permutation = true, identity = true;
  {
    std::vector<char> seen(m, 0);
    size_t i = 0;
    for (size_t hb = 0; hb < hex_blocks.size() && permutation; ++hb)
      for (int64_t e = 0; e < hex_blocks[hb].second && permutation; ++e, ++i) {
        const int64_t t = element_map[hex_block_first[hb] + e];
        if (t < 1 || t > static_cast<int64_t>(m) || seen[t - 1])
          permutation = false;
        else
          seen[t - 1] = 1, slot[i] = static_cast<int32_t>(t - 1);
        identity = identity && t - 1 == static_cast<int64_t>(i);
      }
    identity = identity && permutation;
  }
  std::vector<int64_t>().swap(element_map);
  if (identity) std::vector<int32_t>().swap(slot);
  mesh.attributes.push_back({std::string(attribute_block_id), std::move(block)});
  for (HexAttribute& a : exodus_element_variables(path, hex_blocks))
    mesh.attributes.push_back(std::move(a));
  if (permutation && !identity) {
    std::vector<HexCell> hexes(m);
    for (size_t i = 0; i < m; ++i) hexes[slot[i]] = mesh.hexes[i];
    mesh.hexes = std::move(hexes);
    for (HexAttribute& a : mesh.attributes) {
      std::vector<int32_t> ordered(m);
      for (size_t i = 0; i < m; ++i) ordered[slot[i]] = a.values[i];
      a.values = std::move(ordered);
    }
  }
  return mesh;
}

namespace {

/// Writes the bulk arrays of a netCDF classic file whose header is complete: each variable's
/// values, converted to the file's big-endian type, at the offset its header entry gives.
class ExodusBulkWriter {
 public:
  /// Reads the header of `path` (throws OperationError if it is not a classic netCDF file).
  explicit ExodusBulkWriter(const std::string& path) : path_(path) {
    fd_ = ::open(path.c_str(), O_RDWR | O_CLOEXEC);
    if (fd_ < 0) throw OperationError(std::string("cannot reopen: ") + std::strerror(errno));
    const off_t size = ::lseek(fd_, 0, SEEK_END);
    for (int64_t want = std::min<int64_t>(size, 1 << 20);; want = size) {
      std::string head(static_cast<size_t>(want), '\0');
      if (::pread(fd_, head.data(), head.size(), 0) != static_cast<ssize_t>(head.size()))
        throw OperationError("cannot read back the header");
      try {
        if (std::optional<NetcdfClassicLayout> l = netcdf_classic_layout(path, head, size)) {
          layout_ = std::move(*l);
          break;
        }
      } catch (const InputError& e) {
        throw OperationError(e.what());
      }
      if (want == size) throw OperationError("header longer than the file");
    }
  }
  ~ExodusBulkWriter() {
    if (fd_ >= 0) ::close(fd_);
  }
  ExodusBulkWriter(const ExodusBulkWriter&) = delete;
  ExodusBulkWriter& operator=(const ExodusBulkWriter&) = delete;

  const NetcdfVariableExtent* find(const std::string& name) const {
    for (const NetcdfVariableExtent& v : layout_.variables)
      if (v.name == name) return &v;
    return nullptr;
  }
  const NetcdfVariableExtent& need(const std::string& name) const {
    if (const NetcdfVariableExtent* v = find(name)) return *v;
    throw OperationError("no variable " + name + " in the header just written");
  }

  /// Values value_of(0 .. count - 1) into entries first .. first + count - 1 of `v` (of the
  /// first record, for a record variable).
  template <class ValueOf>
  void put(const NetcdfVariableExtent& v, size_t first, size_t count, ValueOf value_of) {
    const size_t width = v.type == NC_DOUBLE || v.type == NC_INT64 ? 8 : 4;
    if (v.type != NC_DOUBLE && v.type != NC_FLOAT && v.type != NC_INT && v.type != NC_INT64)
      throw OperationError("variable " + v.name + " of netCDF type " + std::to_string(v.type));
    if ((first + count) * width > v.size)
      throw OperationError("variable " + v.name + " holds " + std::to_string(v.size) +
                           " bytes, not " + std::to_string((first + count) * width));
    for (size_t begin = 0; begin < count; begin += exodus_chunk) {
      const size_t end = std::min(count, begin + exodus_chunk);
      buffer_.resize((end - begin) * width);
      unsigned char* out = buffer_.data();
      for (size_t k = begin; k < end; ++k, out += width) {
        const auto value = value_of(k);
        if (v.type == NC_DOUBLE)
          store(value_big_endian(static_cast<double>(value)), out);
        else if (v.type == NC_FLOAT)
          store(value_big_endian(static_cast<float>(value)), out);
        else if (v.type == NC_INT64)
          store(value_big_endian(static_cast<int64_t>(value)), out);
        else
          store(value_big_endian(static_cast<int32_t>(value)), out);
      }
      write_at(v.begin + (first + begin) * width);
    }
  }

  void close() {
    const int fd = fd_;
    fd_ = -1;
    if (::close(fd) != 0) throw OperationError(std::string("close: ") + std::strerror(errno));
  }

 private:
  template <class T>
  static void store(T v, unsigned char* out) {
    std::memcpy(out, &v, sizeof v);
  }
  void write_at(uint64_t offset) {
    const unsigned char* data = buffer_.data();
    size_t left = buffer_.size();
    while (left > 0) {
      const ssize_t wrote = ::pwrite(fd_, data, left, static_cast<off_t>(offset));
      if (wrote <= 0) {
        if (wrote < 0 && errno == EINTR) continue;
        throw OperationError(std::string("write (disk full?): ") + std::strerror(errno));
      }
      data += wrote, offset += static_cast<uint64_t>(wrote), left -= static_cast<size_t>(wrote);
    }
  }

  std::string path_;
  int fd_ = -1;
  NetcdfClassicLayout layout_;
  std::vector<unsigned char> buffer_;
};

}  // namespace

void exodus_write(const std::string& path, const HexMesh& mesh,
                  const std::vector<std::pair<std::string, std::vector<double>>>& cell_scalars) {
  const size_t m = mesh.hexes.size(), n = mesh.points.size();
  const HexBlocks groups = hex_blocks_group(mesh, 1);
  const std::vector<int32_t>& order = groups.order;
  const std::vector<int64_t> blocks(groups.ids.begin(), groups.ids.end());
  // Exodus id of each block: the block_id itself when positive, else a fresh id above them all.
  std::vector<int64_t> exodus_ids(blocks.size());
  int64_t next_id = std::max<int64_t>(blocks.empty() ? 0 : blocks.back(), 0) + 1;
  for (size_t b = 0; b < blocks.size(); ++b) exodus_ids[b] = blocks[b] > 0 ? blocks[b] : next_id++;

  const std::string tmp = file_temporary_beside(path);
  auto failed = [&](const std::string& what) {
    std::remove(tmp.c_str());
    throw OperationError(path + ": cannot write Exodus II file: " + what);
  };
  // Element variables (one time step): every attribute but block_id (the blocks hold it),
  // then the cell scalars, by block in the order of the blocks.
  struct Field {
    std::string name;
    const std::vector<int32_t>* integers;
    const std::vector<double>* reals;
    double operator[](size_t h) const { return integers ? (*integers)[h] : (*reals)[h]; }
  };
  std::vector<Field> fields;
  for (const HexAttribute& a : mesh.attributes)
    if (a.name != attribute_block_id) fields.push_back({a.name, &a.values, nullptr});
  for (const auto& s : cell_scalars) fields.push_back({s.first, nullptr, &s.second});
  if (m == 0) fields.clear();
  ex_opts(EX_DEFAULT);
  {
    int comp_ws = 8, io_ws = 8;
    ExodusFile file;
    // Classic netCDF storage: a header and contiguous arrays, so the bulk data can go straight
    // into place (ExodusBulkWriter, below); and a truncated or corrupted HDF5 file can crash the
    // HDF5 library inside the reader, where the classic header is checked before the library
    // sees it (netcdf_classic_header_check).
    file.id = ex_create(tmp.c_str(), EX_CLOBBER | EX_ALL_INT64_API, &comp_ws, &io_ws);
    if (file.id < 0) failed("cannot create (folder missing or not writable)");
    // Every value below is written, so netCDF's pre-fill of each variable would write the file
    // twice.
    int previous_fill = 0;
    if (nc_set_fill(file.id, NC_NOFILL, &previous_fill) != NC_NOERR) failed("fill mode");
    // Every later definition (the library's own: init, blocks, variables, the id map) grows the
    // header, and netCDF-3 moves all variables defined before it (their full length, written or
    // not) whenever the header outgrows its space: about six moves of up to the whole data
    // section, read and rewritten in 8 KB blocks. A free header space of its own, reserved
    // once, keeps every variable where it was first placed. netCDF computes the space only when
    // a variable exists, hence the one-byte scalar variable defined first (readers ignore it).
    const size_t header_reserve = 65536 + blocks.size() * (1024 + 512 * 8);
    int reserve_id = -1;
    if (nc_redef(file.id) != NC_NOERR ||
        nc_def_var(file.id, "hexrefine_header_reserve", NC_CHAR, 0, nullptr, &reserve_id) !=
            NC_NOERR ||
        nc__enddef(file.id, header_reserve, 4, 0, 4) != NC_NOERR)
      failed("header space");
    // Definitions first, data after: in a classic netCDF file every definition that grows the
    // header moves all data written before it (writing bulk data between definitions rewrote
    // the file two to three times).
    if (ex_put_init(file.id, "hexrefine mesh", 3, static_cast<int64_t>(n), static_cast<int64_t>(m),
                    static_cast<int64_t>(blocks.size()), 0, 0) < 0)
      failed("header");
    char cx[] = "x", cy[] = "y", cz[] = "z";
    char* coordinate_names[] = {cx, cy, cz};
    if (ex_put_coord_names(file.id, coordinate_names) < 0) failed("coordinate names");
    const std::vector<size_t>& block_first = groups.starts;  // hexes of block bi: order[first..)
    for (size_t bi = 0; bi < blocks.size(); ++bi) {
      const int64_t b = blocks[bi], eid = exodus_ids[bi];
      if (ex_put_block(file.id, EX_ELEM_BLOCK, eid, "HEX8",
                       static_cast<int64_t>(block_first[bi + 1] - block_first[bi]), 8, 0, 0, 0) < 0)
        failed("element block " + std::to_string(b));
      if (b <= 0) {
        const std::string name = "hexrefine_block_id=" + std::to_string(b);
        if (ex_put_name(file.id, EX_ELEM_BLOCK, eid, name.c_str()) < 0)
          failed("name of element block " + std::to_string(b));
      }
    }
    if (!fields.empty()) {
      size_t longest = 0;
      for (const Field& f : fields) longest = std::max(longest, f.name.size());
      if (longest > 32 && ex_set_max_name_length(file.id, static_cast<int>(longest)) < 0)
        failed("variable name length");
      if (ex_put_variable_param(file.id, EX_ELEM_BLOCK, static_cast<int>(fields.size())) < 0)
        failed("element variable count");
      std::vector<char*> names;
      for (Field& f : fields) names.push_back(f.name.data());
      if (ex_put_variable_names(file.id, EX_ELEM_BLOCK, static_cast<int>(fields.size()),
                                names.data()) < 0)
        failed("element variable names");
      // The truth table defines every block's variables now rather than at their first write.
      std::vector<int> truth(blocks.size() * fields.size(), 1);
      if (ex_put_truth_table(file.id, EX_ELEM_BLOCK, static_cast<int>(blocks.size()),
                             static_cast<int>(fields.size()), truth.data()) < 0)
        failed("element variable truth table");
    }
    // The element id map is defined at its first write, so its first entry is written here;
    // the time step makes the one record of the element variables. The rest of the bulk data
    // goes in below, once the library has closed the file.
    if (m > 0) {
      const int64_t first = int64_t{order[0]} + 1;
      if (ex_put_partial_id_map(file.id, EX_ELEM_MAP, 1, 1, &first) < 0) failed("element id map");
    }
    if (!fields.empty()) {
      const double time = 0.0;
      if (ex_put_time(file.id, 1, &time) < 0) failed("time step");
    }
    const int id = file.id;
    file.id = -1;
    if (ex_close(id) < 0) failed("close (disk full?)");
  }
  // The bulk arrays, straight into the places the header gives them. Through the library they
  // went in 8 KB blocks, each read from the file before it was written (118,000 reads of holes,
  // which the kernel zero-fills: 0.67 GB read and 0.96 GB written for an 11.4 M-hex mesh, 2 CPU
  // seconds); here they are converted to big-endian (netCDF's byte order) in 1 M-entry chunks
  // and written with one pwrite each.
  try {
    ExodusBulkWriter bulk(tmp);
    for (const char* axis : {"x", "y", "z"}) {
      const int d = axis[0] - 'x';
      if (const NetcdfVariableExtent* v = bulk.find(std::string("coord") + axis))
        bulk.put(*v, 0, n, [&](size_t i) { return mesh.points[i][d]; });
      else if (const NetcdfVariableExtent* all = bulk.find("coord"))  // one (dim, node) array
        bulk.put(*all, static_cast<size_t>(d) * n, n, [&](size_t i) { return mesh.points[i][d]; });
      else if (n > 0)
        throw OperationError("no coordinate variable");
    }
    for (size_t bi = 0; bi < blocks.size(); ++bi) {
      const size_t first = groups.starts[bi], count = groups.starts[bi + 1] - first;
      bulk.put(bulk.need("connect" + std::to_string(bi + 1)), 0, 8 * count,
               [&](size_t k) { return int64_t{mesh.hexes[order[first + k / 8]][k % 8]} + 1; });
      for (size_t f = 0; f < fields.size(); ++f)
        bulk.put(bulk.need("vals_elem_var" + std::to_string(f + 1) + "eb" + std::to_string(bi + 1)),
                 0, count, [&](size_t k) { return fields[f][order[first + k]]; });
    }
    if (m > 0)
      bulk.put(bulk.need("elem_num_map"), 0, m, [&](size_t k) { return int64_t{order[k]} + 1; });
    bulk.close();
  } catch (const OperationError& e) {
    failed(e.what());
  }
  file_commit_temporary(tmp, path);
}

}  // namespace hexrefine::io_detail
