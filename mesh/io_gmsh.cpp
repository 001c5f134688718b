/// \file
/// Gmsh meshes (.msh): format 4.1 read and written, 2.2 (also 2.0/2.1) read; each in text
/// (file type 0) and binary (file type 1; written with MeshWriteOptions::binary). Gmsh element
/// type 5 (8-node hexahedron) has VTK's node order (nodes 0-3 at reference z = -1
/// counter-clockwise, 4-7 above them), so nodes are copied as they are. Nodes and hexes are
/// ordered by tag when their tags are a permutation of 1..n (gmsh itself may list nodes out of tag
/// order), otherwise by file order. The writer is io_gmsh_write.cpp.
///
/// Binary files keep section names, the format line and $ElementData's tag headers as text; the
/// numbers between are the writing machine's values, read here as little-endian (the int 1
/// after the format line tells; a big-endian file is refused). MSH 4.1 stores dimensions, entity
/// tags, element types and physical tags as int (4 bytes); counts and node and element tags as
/// size_t (the format line's data size: 4 or 8 bytes); coordinates as double. MSH 2.2 stores every
/// integer as int, keeps the node and element counts as text, and groups its elements under
/// (type, count, tag count) headers. $ElementData values are (int element tag, doubles) in both.
/// Errors inside binary data name the byte offset ("path: byte N: ..."), elsewhere the line.

#include <algorithm>
#include <map>

#include "mesh/io.hpp"
#include "mesh/io_text.hpp"

namespace hexrefine::io_detail {

namespace {

/// Nodes of Gmsh element type t (0 if unknown); `volume` set for 3D elements.
int gmsh_element_nodes(int64_t t, bool& volume) {
  static const int nodes[] = {0, 2,  3,  4,  4, 8,  6,  5,  3,  6,  9, 10, 27, 18, 14, 1,
                              8, 20, 15, 13, 9, 10, 12, 15, 15, 21, 4, 5,  6,  20, 35, 56};
  volume = t == 4 || t == 5 || t == 6 || t == 7 || t == 11 || t == 12 || t == 13 || t == 14 ||
           t == 17 || t == 18 || t == 19 || t == 29 || t == 30 || t == 31 || t == 92 || t == 93;
  if (t == 92) return 64;
  if (t == 93) return 125;
  if (t < 1 || t > 31) return 0;
  return nodes[t];
}

/// A string tag: a "quoted string" that may span several tokens.
std::string gmsh_string(TextCursor& in) {
  std::string s(in.token("a quoted string"));
  if (s.empty() || s[0] != '"')
    in.fail("expected a quoted string, got '" + TextCursor::shown(s) + "'");
  while (s.size() < 2 || s.back() != '"') {
    if (s.size() > 1000) in.fail("unterminated quoted string");
    s += " ";
    s += in.token("the end of a quoted string");
  }
  return s.substr(1, s.size() - 2);
}

/// The numbers of a section body: tokens of a text file, or values of a binary one (see the
/// file comment). "int" values are 4 bytes in binary; "size" values are size_t in MSH 4.1 and
/// int in MSH 2.2 (`size_bytes`). Positions are lines in text and byte offsets in binary.
class GmshNumbers {
 public:
  GmshNumbers(TextCursor& in, bool binary, int size_bytes)
      : in_(in), binary_(binary), size_bytes_(size_bytes) {}

  bool binary() const { return binary_; }
  TextCursor& text() { return in_; }
  int64_t here() const { return binary_ ? static_cast<int64_t>(in_.position()) : in_.line(); }
  std::string message_at(int64_t where, const std::string& message) const {
    if (!binary_) return error_at(in_.path(), where, message);
    return in_.path() + ": byte " + std::to_string(where) + ": " + message;
  }
  [[noreturn]] void fail(const std::string& message) const { fail_at(here(), message); }
  /// Fails naming position `at` (from here(), taken before the value was read).
  [[noreturn]] void fail_at(int64_t at, const std::string& message) const {
    throw InputError(message_at(at, message));
  }
  /// In a binary file the values start after the line that announced them.
  void begin_values() {
    if (binary_) in_.skip_line();
  }

  int64_t int_value(std::string_view what) {
    if (!binary_) return in_.integer(what);
    int32_t v;
    std::memcpy(&v, bytes(4, what), 4);
    return v;
  }
  int64_t size_value(std::string_view what) {
    if (!binary_) return in_.integer(what);
    if (size_bytes_ == 4) return int_value(what);
    const int64_t at = here();
    uint64_t v;
    std::memcpy(&v, bytes(8, what), 8);
    if (v > static_cast<uint64_t>(INT64_MAX))
      fail_at(at, std::string(what) + " " + std::to_string(v) + " out of range");
    return static_cast<int64_t>(v);
  }
  int64_t int_in(std::string_view what, int64_t lo, int64_t hi) {
    const int64_t at = here();
    const int64_t v = int_value(what);
    if (v < lo || v > hi)
      fail_at(at, "expected " + std::string(what) + " in " + std::to_string(lo) + ".." +
                      std::to_string(hi) + ", got " + std::to_string(v));
    return v;
  }
  double real(std::string_view what) {
    if (!binary_) return in_.real(what);
    const int64_t at = here();
    double v;
    std::memcpy(&v, bytes(8, what), 8);
    if (!std::isfinite(v)) fail_at(at, "expected " + std::string(what) + " (a finite number)");
    return v;
  }
  /// A size value in [0, limit] whose items need at least `text_bytes` (`binary_bytes`) each of
  /// what remains of the file; checked before the caller allocates anything.
  int64_t count(std::string_view what, int64_t text_bytes, int64_t binary_bytes,
                int64_t limit = INT32_MAX) {
    const int64_t at = here();
    const int64_t n = size_value(what);
    const int64_t each = binary_ ? binary_bytes : text_bytes;
    if (n < 0) fail_at(at, "expected " + std::string(what) + " >= 0, got " + std::to_string(n));
    if (n > limit)
      fail_at(at, std::string(what) + " " + std::to_string(n) + " exceeds the limit " +
                      std::to_string(limit));
    if (each > 0 && n > static_cast<int64_t>(in_.remaining()) / each)
      fail_at(at, std::string(what) + " " + std::to_string(n) +
                      " is more than the rest of the file (" + std::to_string(in_.remaining()) +
                      " bytes) can hold");
    return n;
  }
  /// Skips `n` size values (text tokens or binary).
  void skip_sizes(int64_t n, std::string_view what) {
    if (!binary_) {
      for (int64_t k = 0; k < n; ++k) in_.integer(what);
      return;
    }
    if (n > static_cast<int64_t>(in_.remaining()) / size_bytes_)
      fail("file ends inside " + std::string(what));
    bytes(static_cast<size_t>(n) * size_bytes_, what);
  }

 private:
  const char* bytes(size_t n, std::string_view what) {
    if (n > in_.remaining())
      fail("file ends inside " + std::string(what) + " (" + std::to_string(n) +
           " bytes expected, " + std::to_string(in_.remaining()) + " left)");
    return in_.raw(n, what, false);
  }

  TextCursor& in_;
  bool binary_;
  int size_bytes_;
};

/// What the sections leave for the end of gmsh_read. Hexes are stored as node indices at once
/// ($Nodes precedes $Elements, so the node index exists), and $ElementData fields as int32
/// values, keyed by position while their element tags run 1, 2, 3, ...: the intermediate stays
/// small beside the file for a 10 M-hex mesh.
struct GmshRead {
  HexMesh mesh;
  std::vector<int64_t> node_tags;
  IdIndex nodes;  ///< node tag -> index, built when $Elements starts
  std::vector<int64_t> hex_tags;
  std::vector<int64_t> hex_where;  ///< line or byte offset, for messages
  std::vector<int32_t> hex_block;
  struct Data {
    std::string name;
    std::vector<int64_t> tags;    ///< the element tags, empty while they are 1, 2, ..., count
    std::vector<int32_t> values;  ///< in file order; cleared once a value is not an int32
    bool integral = true;
  };
  std::vector<Data> element_data;
  /// The mapped file (nullptr: not mapped) and its text: the bytes up to `released` are
  /// handed back to the system as they are read (FileBytes::release).
  const FileBytes* file = nullptr;
  std::string_view text;
  size_t released = 0;
  /// Releases what the cursor has passed, in steps of 64 MB (a section can be most of a file).
  void release_read(size_t position) {
    constexpr size_t step = size_t{64} << 20;
    if (file == nullptr || position < released + step) return;
    file->release(text.substr(released, position - released));
    released = position;
  }
};

/// Room for `count` hexes (an upper bound the file's size was checked against), so that a large
/// file is not read into vectors that grow by copying.
void gmsh_hexes_reserve(GmshRead& g, int64_t count) {
  const size_t n = static_cast<size_t>(count);
  g.mesh.hexes.reserve(n);
  g.hex_tags.reserve(n);
  g.hex_where.reserve(n);
  g.hex_block.reserve(n);
}

/// Reads the nodes of one element of type `type` (its tag already read); keeps it if it is a hex.
void gmsh_element_nodes_read(GmshNumbers& in, GmshRead& g, int64_t type, int64_t tag, int32_t block,
                             int64_t where) {
  bool volume = false;
  const int n = gmsh_element_nodes(type, volume);
  if (n == 0) in.fail("unknown Gmsh element type " + std::to_string(type));
  if (volume && type != 5)
    in.fail("element " + std::to_string(tag) + " has Gmsh type " + std::to_string(type) +
            ", a volume element that is not a linear hexahedron (only type 5 is supported)");
  if (type != 5) {
    in.skip_sizes(n, "node tag");
    return;
  }
  HexCell cell;
  for (int k = 0; k < 8; ++k) {
    const int64_t node = in.size_value("node tag");
    const int64_t v = g.nodes.find(node);
    if (v < 0)
      throw InputError(in.message_at(where, "hex element " + std::to_string(tag) +
                                                " refers to undefined node " +
                                                std::to_string(node)));
    cell[k] = static_cast<int32_t>(v);
  }
  g.mesh.hexes.push_back(cell);
  if ((g.mesh.hexes.size() & 0xFFFF) == 0) g.release_read(in.text().position());
  g.hex_tags.push_back(tag);
  g.hex_where.push_back(where);
  g.hex_block.push_back(block);
}

/// Skips a section this reader does not use. Binary sections are skipped by searching their end
/// marker, since their bytes are not tokens.
void gmsh_skip_section(GmshNumbers& in, std::string_view name) {
  const std::string end = "$End" + std::string(name.substr(1));
  if (in.binary()) {
    if (!in.text().skip_to(end)) in.fail("section " + std::string(name) + " without " + end);
    in.text().expect(end);
    return;
  }
  const std::string expected = "'" + end + "'";
  while (in.text().token(expected) != end) {
  }
}

/// $MeshFormat: the version (4.1 or 2.x), the encoding and, for binary, the size_t width and
/// the byte order.
struct GmshFormat {
  bool v4;
  bool binary;
  int size_bytes;
};

GmshFormat gmsh_format_read(TextCursor& in) {
  in.expect("$MeshFormat");
  const double version = in.real("the format version");
  const int64_t file_type = in.integer_in("the file type (0 text, 1 binary)", 0, 1);
  const int64_t data_size = in.integer("the data size");
  GmshFormat f{version >= 4.05 && version < 5, file_type == 1, 4};
  if (!f.v4 && !(version >= 2 && version < 3))
    in.fail("Gmsh format " + std::to_string(version) + " is not supported (expected 4.1 or 2.2)");
  if (f.binary) {
    if (data_size != 4 && data_size != 8)
      in.fail("binary Gmsh data size " + std::to_string(data_size) + ": expected 4 or 8");
    f.size_bytes = f.v4 ? static_cast<int>(data_size) : 4;
    in.skip_line();
    int32_t one;
    std::memcpy(&one, in.raw(4, "the binary byte-order mark", false), 4);
    if (one != 1)
      in.fail(one == 0x01000000 ? "big-endian binary Gmsh files are not supported"
                                : "binary Gmsh file without its byte-order mark (int 1)");
  }
  in.expect("$EndMeshFormat");
  return f;
}

void gmsh_entities_read(GmshNumbers& in, std::map<int64_t, int32_t>& volume_physical) {
  in.begin_values();
  int64_t counts[4];
  for (int64_t& c : counts) c = in.count("entity count", 4, 4 + 3 * 8);
  for (int dim = 0; dim < 4; ++dim)
    for (int64_t e = 0; e < counts[dim]; ++e) {
      const int64_t tag = in.int_value("entity tag");
      for (int k = 0; k < (dim == 0 ? 3 : 6); ++k) in.real("entity bounding box");
      const int64_t nphys = in.count("physical tag count", 2, 4);
      for (int64_t k = 0; k < nphys; ++k) {
        const int64_t phys = in.int_value("physical tag");
        if (dim == 3 && k == 0) {
          if (phys < INT32_MIN || phys > INT32_MAX) in.fail("physical tag out of range");
          volume_physical[tag] = static_cast<int32_t>(phys);
        }
      }
      if (dim > 0) {
        const int64_t nb = in.count("bounding entity count", 2, 4);
        for (int64_t k = 0; k < nb; ++k) in.int_value("bounding entity tag");
      }
    }
  in.text().expect("$EndEntities");
}

void gmsh_nodes_read(GmshNumbers& in, const GmshFormat& f, GmshRead& g) {
  if (f.v4) {
    in.begin_values();
    const int64_t blocks = in.count("node block count", 8, 12 + f.size_bytes);
    const int64_t total = in.count("node count", 8, f.size_bytes + 24);
    in.size_value("min node tag");
    in.size_value("max node tag");
    g.node_tags.reserve(static_cast<size_t>(total));
    g.mesh.points.reserve(static_cast<size_t>(total));
    for (int64_t b = 0; b < blocks; ++b) {
      const int64_t dim = in.int_in("entity dimension", 0, 3);
      in.int_value("entity tag");
      const int64_t parametric = in.int_in("parametric flag", 0, 1);
      const int64_t n = in.count("nodes in block", 8, f.size_bytes + 24);
      if (static_cast<int64_t>(g.node_tags.size()) + n > total)
        in.fail("node blocks hold more than the " + std::to_string(total) + " nodes announced");
      for (int64_t i = 0; i < n; ++i) g.node_tags.push_back(in.size_value("node tag"));
      for (int64_t i = 0; i < n; ++i) {
        Eigen::Vector3d p;
        for (int k = 0; k < 3; ++k) p[k] = in.real("node coordinate");
        if (parametric)
          for (int64_t k = 0; k < dim; ++k) in.real("parametric coordinate");
        g.mesh.points.push_back(p);
        if ((g.mesh.points.size() & 0xFFFF) == 0) g.release_read(in.text().position());
      }
    }
    if (static_cast<int64_t>(g.node_tags.size()) != total)
      in.fail("node blocks hold " + std::to_string(g.node_tags.size()) + " nodes, " +
              std::to_string(total) + " announced");
  } else {
    const int64_t n = in.text().count("node count", in.binary() ? 28 : 8);
    in.begin_values();
    g.node_tags.reserve(static_cast<size_t>(n));
    g.mesh.points.resize(static_cast<size_t>(n));
    for (int64_t i = 0; i < n; ++i) {
      g.node_tags.push_back(in.size_value("node tag"));
      for (int k = 0; k < 3; ++k) g.mesh.points[i][k] = in.real("node coordinate");
      if ((i & 0xFFFF) == 0) g.release_read(in.text().position());
    }
  }
  in.text().expect("$EndNodes");
}

void gmsh_elements_read(GmshNumbers& in, const GmshFormat& f, GmshRead& g,
                        const std::map<int64_t, int32_t>& volume_physical) {
  if (f.v4) {
    in.begin_values();
    const int64_t blocks = in.count("element block count", 8, 12 + f.size_bytes);
    const int64_t total = in.count("element count", 4, 2 * f.size_bytes);
    in.size_value("min element tag");
    in.size_value("max element tag");
    gmsh_hexes_reserve(g, total);
    int64_t seen = 0;
    for (int64_t b = 0; b < blocks; ++b) {
      const int64_t dim = in.int_in("entity dimension", 0, 3);
      const int64_t entity = in.int_value("entity tag");
      const int64_t type = in.int_value("element type");
      const int64_t n = in.count("elements in block", 4, 2 * f.size_bytes);
      seen += n;
      if (seen > total)
        in.fail("element blocks hold more than the " + std::to_string(total) +
                " elements announced");
      int32_t block = 0;
      if (dim == 3) {
        const auto it = volume_physical.find(entity);
        if (it != volume_physical.end()) block = it->second;
      }
      for (int64_t i = 0; i < n; ++i) {
        // Binary: the row's first byte; text: the line of its tag (read first).
        const int64_t before = in.here();
        const int64_t tag = in.size_value("element tag");
        gmsh_element_nodes_read(in, g, type, tag, block, in.binary() ? before : in.here());
      }
    }
    if (seen != total)
      in.fail("element blocks hold " + std::to_string(seen) + " elements, " +
              std::to_string(total) + " announced");
  } else if (!in.binary()) {
    TextCursor& text = in.text();
    const int64_t n = text.count("element count", 8);
    gmsh_hexes_reserve(g, n);
    for (int64_t i = 0; i < n; ++i) {
      const int64_t tag = text.integer("element tag");
      const int64_t where = in.here();
      const int64_t type = text.integer("element type");
      const int64_t ntags = text.integer_in("tag count", 0, 64);
      int32_t block = 0;
      for (int64_t k = 0; k < ntags; ++k) {
        const int64_t t = text.integer("element tag value");
        if (k == 0) {
          if (t < INT32_MIN || t > INT32_MAX) text.fail("physical tag out of range");
          block = static_cast<int32_t>(t);
        }
      }
      gmsh_element_nodes_read(in, g, type, tag, block, where);
    }
  } else {
    // Binary 2.2: groups of elements of one type, each headed by (type, count, tag count).
    const int64_t n = in.text().count("element count", 12);
    gmsh_hexes_reserve(g, n);
    in.begin_values();
    for (int64_t seen = 0; seen < n;) {
      const int64_t type = in.int_value("element type");
      const int64_t count = in.int_in("elements in group", 1, n - seen);
      const int64_t ntags = in.int_in("tag count", 0, 64);
      for (int64_t i = 0; i < count; ++i) {
        const int64_t where = in.here();
        const int64_t tag = in.int_value("element tag");
        int32_t block = 0;
        for (int64_t k = 0; k < ntags; ++k) {
          const int64_t t = in.int_value("element tag value");
          if (k == 0) block = static_cast<int32_t>(t);
        }
        gmsh_element_nodes_read(in, g, type, tag, block, where);
      }
      seen += count;
    }
  }
  in.text().expect("$EndElements");
}

/// $ElementData: the tag headers are text in both encodings; single-component fields with a
/// name are kept.
void gmsh_element_data_read(GmshNumbers& in, GmshRead& g) {
  TextCursor& text = in.text();
  GmshRead::Data d;
  const int64_t nstrings = text.integer_in("string tag count", 0, 64);
  for (int64_t k = 0; k < nstrings; ++k) {
    const std::string s = gmsh_string(text);
    if (k == 0) d.name = s;
  }
  const int64_t nreals = text.integer_in("real tag count", 0, 64);
  for (int64_t k = 0; k < nreals; ++k) text.real("real tag");
  const int64_t nints = text.integer_in("integer tag count", 3, 64);
  int64_t components = 1, count = 0;
  for (int64_t k = 0; k < nints; ++k) {
    const int64_t v = text.integer("integer tag");
    if (k == 1) components = v;
    if (k == 2) count = v;
  }
  if (components < 1 || components > 9)
    text.fail("bad component count " + std::to_string(components));
  text.check_count(count, "element data count",
                   in.binary() ? 4 + 8 * components : 2 * (1 + components));
  in.begin_values();
  const bool keep = components == 1 && !d.name.empty();
  if (keep) d.values.reserve(static_cast<size_t>(count));
  // Value v (NaN or infinite: 0.5, not an integer) of the element with tag `tag`, the i-th.
  auto element_value_take = [&](int64_t i, int64_t tag, double v) {
    if (!keep || !d.integral) return;
    if (v != std::floor(v) || v < INT32_MIN || v > INT32_MAX) {
      d.integral = false;
      d.values = {};
      d.tags = {};
      return;
    }
    if (d.tags.empty() && tag != i + 1) {  // tags not 1, 2, ...: keep them from here on
      d.tags.reserve(static_cast<size_t>(count));
      for (int64_t k = 0; k < i; ++k) d.tags.push_back(k + 1);
    }
    if (!d.tags.empty() || tag != i + 1) d.tags.push_back(tag);
    d.values.push_back(static_cast<int32_t>(v));
  };
  if (in.binary()) {
    // Records of an int tag and `components` doubles: the whole block taken at once (its size
    // was checked against the file above), then read in place.
    const size_t record = 4 + 8 * static_cast<size_t>(components);
    const char* p = text.raw(static_cast<size_t>(count) * record, "element data", false);
    for (int64_t i = 0; i < count; ++i, p += record) {
      int32_t tag;
      std::memcpy(&tag, p, 4);
      for (int64_t c = 0; c < components; ++c) {
        double v;
        std::memcpy(&v, p + 4 + 8 * c, 8);
        element_value_take(i, tag, std::isfinite(v) ? v : 0.5);
      }
    }
  } else {
    for (int64_t i = 0; i < count; ++i) {
      const int64_t tag = text.integer("element tag");
      for (int64_t c = 0; c < components; ++c) {
        double v = 0.5;
        if (!TextCursor::parse_real(text.token("element data value"), v)) v = 0.5;
        element_value_take(i, tag, v);
      }
    }
  }
  text.expect("$EndElementData");
  if (keep && d.integral) g.element_data.push_back(std::move(d));
}

}  // namespace

HexMesh gmsh_read(const std::string& path, std::string_view text, const FileBytes* file) {
  TextCursor cursor(path, text);
  const GmshFormat f = gmsh_format_read(cursor);
  GmshNumbers in(cursor, f.binary, f.size_bytes);
  GmshRead g;
  g.file = file;
  g.text = text;
  std::map<int64_t, int32_t> volume_physical;  // volume entity tag -> first physical tag
  bool have_nodes = false, have_elements = false;
  while (!cursor.at_end()) {
    // What a section held is in the mesh being built once it is read: its bytes go.
    g.release_read(cursor.position());
    const std::string_view section = cursor.token("a section");
    if (section == "$Entities" && f.v4) {
      gmsh_entities_read(in, volume_physical);
    } else if (section == "$Nodes") {
      if (have_nodes) cursor.fail("second $Nodes section");
      have_nodes = true;
      gmsh_nodes_read(in, f, g);
    } else if (section == "$Elements") {
      if (have_elements) cursor.fail("second $Elements section");
      if (!have_nodes) cursor.fail("$Elements before $Nodes (Gmsh files list the nodes first)");
      have_elements = true;
      items_sort_by_permutation_ids(g.mesh.points, g.node_tags);
      if (const int64_t bad = g.nodes.build(g.node_tags); bad >= 0)
        cursor.fail("node tag " + std::to_string(g.node_tags[bad]) + " repeated or not positive");
      g.node_tags = {};
      gmsh_elements_read(in, f, g, volume_physical);
    } else if (section == "$ElementData") {
      gmsh_element_data_read(in, g);
    } else if (!section.empty() && section[0] == '$' && section.substr(0, 4) != "$End") {
      gmsh_skip_section(in, section);
    } else {
      cursor.fail("expected a section such as $Nodes or $Elements, got '" +
                  TextCursor::shown(section) + "'");
    }
  }
  if (!have_nodes || !have_elements) cursor.fail("expected $Nodes and $Elements sections");

  if (g.hex_tags.size() > INT32_MAX) cursor.fail("too many hexes");
  const size_t m = g.hex_tags.size();
  IdIndex hexes;
  if (const int64_t bad = hexes.build(g.hex_tags); bad >= 0)
    throw InputError(in.message_at(
        g.hex_where[bad],
        "element tag " + std::to_string(g.hex_tags[bad]) + " repeated or not positive"));
  // Positions were kept for that message, the node index for the elements: both done with.
  std::vector<int64_t>().swap(g.hex_where);
  g.nodes = IdIndex();
  // Order: by tag when the hex tags are exactly 1..m, else file order. Already in tag order
  // (what hexrefine and gmsh write), nothing moves: no second copy of the cells.
  std::vector<int32_t> slot = id_permutation_slots(g.hex_tags);
  // Hex i has tag i + 1: then a field keyed by position 1, 2, ... is in hex order too.
  bool hexes_in_tag_order = !slot.empty();
  for (size_t i = 0; i < slot.size() && hexes_in_tag_order; ++i)
    hexes_in_tag_order = slot[i] == static_cast<int32_t>(i);
  if (hexes_in_tag_order) std::vector<int32_t>().swap(slot);
  if (!slot.empty()) {
    std::vector<HexCell> cells(m);
    std::vector<int32_t> blocks(m);
    for (size_t i = 0; i < m; ++i) {
      cells[slot[i]] = g.mesh.hexes[i];
      blocks[slot[i]] = g.hex_block[i];
    }
    g.mesh.hexes = std::move(cells);
    g.hex_block = std::move(blocks);
  }
  auto slot_of = [&](size_t i) { return slot.empty() ? static_cast<int32_t>(i) : slot[i]; };
  g.mesh.attributes.push_back({std::string(attribute_block_id), std::move(g.hex_block)});
  for (GmshRead::Data& d : g.element_data) {
    std::vector<int32_t> values;
    if (d.tags.empty() && slot.empty() && d.values.size() == m && hexes_in_tag_order) {
      values = std::move(d.values);  // one value per hex, in hex order already
    } else {
      values.assign(m, 0);
      for (size_t k = 0; k < d.values.size(); ++k) {
        const int64_t i = hexes.find(d.tags.empty() ? static_cast<int64_t>(k) + 1 : d.tags[k]);
        if (i >= 0) values[slot_of(static_cast<size_t>(i))] = d.values[k];  // else: skipped
      }
    }
    d.values = {};
    d.tags = {};
    if (mesh_find_attribute(g.mesh, d.name) != nullptr) {
      // block_id from $ElementData overrides the physical tags (it also holds ids <= 0); other
      // repeated names are later time steps of a field already read.
      if (d.name == attribute_block_id) mesh_attribute(g.mesh, d.name) = std::move(values);
      continue;
    }
    g.mesh.attributes.push_back({d.name, std::move(values)});
  }
  // The tags and their index are done with: they go before the manifold test builds its face
  // slots (peak memory).
  std::vector<int64_t>().swap(g.hex_tags);
  hexes = IdIndex();
  return std::move(g.mesh);
}

}  // namespace hexrefine::io_detail
