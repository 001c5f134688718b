#pragma once
/// \file
/// Private to the mesh readers and writers. Readers: a whole-file buffer with a line-counting
/// tokenizer, number parsing that refuses garbage, NaN and infinity, and size checks made before
/// anything is allocated. Writers: TextWriter, one buffer that numbers are formatted into with
/// std::to_chars and that goes to the stream in large chunks.

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <ostream>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "mesh/error.hpp"
#include "mesh/hex_mesh.hpp"

namespace hexrefine::io_detail {

/// The whole file as bytes; InputError naming the path if it cannot be opened or read.
std::string file_read_all(const std::string& path);

/// The bytes of a file for a reader: a regular file is mapped read-only (mmap), so a large file
/// costs neither a copy nor a zero-filled buffer of its size (on the 2-core machine the two were
/// a third of the time to read a 1.7 GB binary Gmsh file); anything else (a pipe, a file that
/// cannot be mapped) is read with file_read_all. InputError naming the path if the file cannot
/// be opened or read. The mapping is private; like any reader of a file, it expects the file not
/// to be truncated by another process while it reads (hexrefine's own writers replace files by
/// rename, which leaves a mapped file intact).
class FileBytes {
 public:
  explicit FileBytes(const std::string& path);
  ~FileBytes();
  FileBytes(const FileBytes&) = delete;
  FileBytes& operator=(const FileBytes&) = delete;
  std::string_view view() const { return map_ ? std::string_view(map_, size_) : copy_; }
  /// Tells the system that `part` (a slice of view()) has been consumed: the whole pages inside
  /// it leave this process' resident memory (madvise MADV_DONTNEED). The bytes stay readable: a
  /// private read-only mapping faults them in again from the file. A reader that has copied a
  /// large array out of the file calls this so that the file and the copy do not both count in
  /// its peak. Nothing happens for a copied (not mapped) file or a slice outside the mapping.
  void release(std::string_view part) const;

 private:
  const char* map_ = nullptr;
  size_t size_ = 0;
  std::string copy_;
};

/// Tokens separated by white space (and by `extra_separators`, e.g. "," for Abaqus); `comment`
/// (if not 0) starts a comment running to the end of the line. Tracks the 1-based line number
/// of the last token for error messages. The text is borrowed: it must outlive the cursor.
/// `what` arguments (what the caller expects, for messages) are string views so that the hot
/// per-token calls with a literal build no std::string; messages are built only on failure.
/// Newline bytes in p[0, n): line numbers after a binary block count them too. Sixteen byte-wide
/// counters over blocks of 255 x 16 bytes (none can overflow), which the compiler turns into
/// byte-wise vector adds: several times faster than std::count's 64-bit lanes or a byte loop,
/// where counting would otherwise be a noticeable part of reading a large binary file (figures:
/// results/bench/README.md, "Figures behind the code's comments").
inline size_t bytes_count_newlines(const char* p, size_t n) {
  size_t total = 0;
  while (n > 0) {
    const size_t m = std::min<size_t>(n, 255 * 16);
    uint8_t lanes[16] = {};
    size_t i = 0;
    for (; i + 16 <= m; i += 16)
      for (int k = 0; k < 16; ++k) lanes[k] += p[i + k] == '\n';
    for (; i < m; ++i) total += p[i] == '\n';
    for (uint8_t lane : lanes) total += lane;
    p += m;
    n -= m;
  }
  return total;
}

class TextCursor {
 public:
  TextCursor(const std::string& path, std::string_view text, char comment = 0,
             const char* extra_separators = "")
      : path_(path), text_(text), comment_(comment) {
    // Byte classes as tables: the tokenizer looks at every byte of the file.
    for (const char c : {' ', '\t', '\r', '\f', '\v'}) blank_[static_cast<unsigned char>(c)] = true;
    for (const char* e = extra_separators; *e != 0; ++e)
      blank_[static_cast<unsigned char>(*e)] = true;
    stop_ = blank_;
    stop_['\n'] = true;
    // comment == 0 means "no comment character": a NUL byte is then part of the token (which
    // will not parse), never an empty token that would stall a caller's loop.
    if (comment_ != 0) stop_[static_cast<unsigned char>(comment_)] = true;
  }

  const std::string& path() const { return path_; }
  /// For a cursor over a slice of a file: the line number of the slice's first byte.
  void set_line(int64_t line) { line_ = line; }
  int64_t line() const { return line_; }
  size_t position() const { return pos_; }
  /// Bytes not yet consumed.
  size_t remaining() const { return text_.size() - pos_; }

  /// Throws InputError "path:line: message".
  [[noreturn]] void fail(const std::string& message) const {
    throw InputError(error_at(path_, line_, message));
  }

  /// True when only white space and comments remain.
  bool at_end() {
    skip_space();
    return pos_ >= text_.size();
  }

  /// The next token; at the end of the file fails with "unexpected end of file, expected <what>".
  std::string_view token(std::string_view what) {
    skip_space();
    if (pos_ >= text_.size()) fail("unexpected end of file, expected " + std::string(what));
    const size_t start = pos_;
    while (pos_ < text_.size() && !stop_[static_cast<unsigned char>(text_[pos_])]) ++pos_;
    return text_.substr(start, pos_ - start);
  }

  /// The next token without consuming it (empty at the end).
  std::string_view peek() {
    const size_t pos = pos_;
    const int64_t line = line_;
    skip_space();
    if (pos_ >= text_.size()) {
      pos_ = pos, line_ = line;
      return {};
    }
    const std::string_view t = token("");
    pos_ = pos, line_ = line;
    return t;
  }

  /// An integer token; fails naming `what` on anything else.
  int64_t integer(std::string_view what) {
    const std::string_view t = token(what);
    int64_t v = 0;
    if (!parse_integer(t, v))
      fail("expected " + std::string(what) + " (an integer), got '" + shown(t) + "'");
    return v;
  }

  /// An integer in [lo, hi].
  int64_t integer_in(std::string_view what, int64_t lo, int64_t hi) {
    const int64_t v = integer(what);
    if (v < lo || v > hi)
      fail("expected " + std::string(what) + " in " + std::to_string(lo) + ".." +
           std::to_string(hi) + ", got " + std::to_string(v));
    return v;
  }

  /// A finite real token.
  double real(std::string_view what) {
    const std::string_view t = token(what);
    double v = 0;
    if (!parse_real(t, v))
      fail("expected " + std::string(what) + " (a finite number), got '" + shown(t) + "'");
    return v;
  }

  /// Consumes the next token and fails unless it equals `word` (case-insensitive).
  void expect(std::string_view word) {
    std::string quoted(1, '\'');
    quoted.append(word);
    quoted.push_back('\'');
    const std::string_view t = token(quoted);
    if (!same_word(t, word)) fail("expected " + quoted + ", got '" + shown(t) + "'");
  }

  /// A count in [0, limit] whose items need at least `min_bytes_each` bytes of what remains of
  /// the file; checked before the caller allocates anything.
  int64_t count(std::string_view what, int64_t min_bytes_each, int64_t limit = INT32_MAX) {
    const int64_t n = integer(what);
    check_count(n, what, min_bytes_each, limit);
    return n;
  }

  void check_count(int64_t n, std::string_view what, int64_t min_bytes_each,
                   int64_t limit = INT32_MAX) const {
    if (n < 0) fail("expected " + std::string(what) + " >= 0, got " + std::to_string(n));
    if (n > limit)
      fail(std::string(what) + " " + std::to_string(n) + " exceeds the limit " +
           std::to_string(limit));
    if (min_bytes_each > 0 && n > static_cast<int64_t>(remaining()) / min_bytes_each)
      fail(std::string(what) + " " + std::to_string(n) + " is more than the rest of the file (" +
           std::to_string(remaining()) + " bytes) can hold");
  }

  /// Skips the rest of the current line, including its newline.
  void skip_line() {
    while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
    if (pos_ < text_.size()) ++pos_, ++line_;
  }

  /// The rest of the current line (without the newline), consumed.
  std::string_view rest_of_line() {
    const size_t start = pos_;
    while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
    std::string_view s = text_.substr(start, pos_ - start);
    if (pos_ < text_.size()) ++pos_, ++line_;
    if (!s.empty() && s.back() == '\r') s.remove_suffix(1);
    return s;
  }

  /// `n` raw bytes (for binary blocks), consumed; fails naming `what` if the file is shorter.
  /// `count_lines` false skips counting the newline bytes inside them (a file whose positions
  /// are reported as byte offsets has no use for line numbers, and the scan costs a pass).
  const char* raw(size_t n, std::string_view what, bool count_lines = true) {
    if (n > remaining())
      fail("file ends inside " + std::string(what) + " (" + std::to_string(n) +
           " bytes expected, " + std::to_string(remaining()) + " left)");
    const char* p = text_.data() + pos_;
    if (count_lines) line_ += static_cast<int64_t>(bytes_count_newlines(p, n));
    pos_ += n;
    return p;
  }

  /// Moves to the first occurrence of `needle` at or after the position; false (position
  /// unchanged) if there is none. Lines are not counted: for skipping binary blocks.
  bool skip_to(std::string_view needle) {
    const size_t at = text_.find(needle, pos_);
    if (at == std::string_view::npos) return false;
    pos_ = at;
    return true;
  }

  static bool parse_integer(std::string_view t, int64_t& v) {
    if (!t.empty() && t[0] == '+') t.remove_prefix(1);
    const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
    return !t.empty() && r.ec == std::errc() && r.ptr == t.data() + t.size();
  }
  static bool parse_real(std::string_view t, double& v) {
    if (!t.empty() && t[0] == '+') t.remove_prefix(1);
    const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
    return !t.empty() && r.ec == std::errc() && r.ptr == t.data() + t.size() && std::isfinite(v);
  }
  static bool same_word(std::string_view a, std::string_view b) {
    if (a.size() != b.size()) return false;
    for (size_t i = 0; i < a.size(); ++i)
      if (lower(a[i]) != lower(b[i])) return false;
    return true;
  }
  static char lower(char c) { return (c >= 'A' && c <= 'Z') ? static_cast<char>(c + 32) : c; }
  /// A token made safe to print: at most 40 characters, non-printable bytes as '?'.
  static std::string shown(std::string_view t) {
    std::string s(t.substr(0, 40));
    for (char& c : s)
      if (static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) > 126) c = '?';
    if (t.size() > 40) s += "...";
    return s;
  }

 private:
  void skip_space() {
    while (pos_ < text_.size()) {
      const char c = text_[pos_];
      if (c == '\n') {
        ++line_, ++pos_;
      } else if (blank_[static_cast<unsigned char>(c)]) {
        ++pos_;
      } else if (comment_ != 0 && c == comment_) {
        while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
      } else {
        break;
      }
    }
  }

  std::string path_;
  std::string_view text_;
  char comment_;
  std::array<bool, 256> blank_{};  ///< white space other than '\n', and the extra separators
  std::array<bool, 256> stop_{};   ///< ends a token: blank_, '\n' and the comment character
  size_t pos_ = 0;
  int64_t line_ = 1;
};

/// Maps arbitrary positive file ids (node or element tags) to 0-based indices. Dense when the
/// ids are compact (max id <= 4 * count + 1024), otherwise sorted pairs with binary search.
class IdIndex {
 public:
  /// Builds the index; `ids[i]` is the file id of item i. Returns the position of a repeated id,
  /// or -1 when all ids are distinct and >= 1.
  int64_t build(const std::vector<int64_t>& ids);
  /// Index of file id `id`, or -1.
  int64_t find(int64_t id) const;

 private:
  std::vector<int32_t> dense_;
  std::vector<std::pair<int64_t, int32_t>> sorted_;
  bool is_dense_ = true;
};

/// When `ids` is a permutation of 1..n: slot i = ids[i] - 1 for every item; otherwise empty.
/// Readers use it to put items with such ids in id order (files written by other tools, e.g.
/// gmsh, may list nodes in another order than their tags).
std::vector<int32_t> id_permutation_slots(const std::vector<int64_t>& ids);

/// Reorders `items` (one per id) into id order when id_permutation_slots(ids) is not empty, and
/// rewrites `ids` to 1..n to match. Returns whether it reordered.
template <class T>
bool items_sort_by_permutation_ids(std::vector<T>& items, std::vector<int64_t>& ids) {
  const std::vector<int32_t> slot = id_permutation_slots(ids);
  if (slot.empty() || slot.size() != items.size()) return false;
  std::vector<T> sorted(items.size());
  for (size_t i = 0; i < items.size(); ++i) sorted[slot[i]] = std::move(items[i]);
  items = std::move(sorted);
  for (size_t i = 0; i < ids.size(); ++i) ids[i] = static_cast<int64_t>(i) + 1;
  return true;
}

/// The checks every read ends with (mesh_read runs them on what the reader returns): ids in range
/// and distinct per hex (mesh_validate_ids), then, with `manifold_test`, mesh_require_manifold.
void mesh_check_read(const HexMesh& mesh, const std::string& path, bool manifold_test);

/// Hexes grouped by block_id, for the writers that store one block per id (Exodus element
/// blocks, Gmsh volume entities, Abaqus element sets): `ids` ascending and distinct; the hexes of
/// ids[b] are order[starts[b] .. starts[b + 1]), ascending. Without a block_id attribute every
/// hex is in one block `default_id`; no hexes, no blocks. A counting sort when the ids span at
/// most the hex count (+1024), a sort of (id, hex) pairs otherwise.
struct HexBlocks {
  std::vector<int32_t> ids;
  std::vector<int32_t> order;
  std::vector<size_t> starts;  ///< ids.size() + 1 entries
};
HexBlocks hex_blocks_group(const HexMesh& mesh, int32_t default_id);

/// `v` with its bytes in big-endian order (VTK legacy binary), for 2-, 4- and 8-byte numbers.
template <class T>
T value_big_endian(T v) {
  static_assert(std::is_trivially_copyable_v<T> &&
                (sizeof(T) == 2 || sizeof(T) == 4 || sizeof(T) == 8));
  static_assert(std::endian::native == std::endian::little ||
                std::endian::native == std::endian::big);
  if constexpr (std::endian::native == std::endian::big) {
    return v;
  } else {
    using U = std::conditional_t<sizeof(T) == 2, uint16_t,
                                 std::conditional_t<sizeof(T) == 4, uint32_t, uint64_t>>;
    U u;
    std::memcpy(&u, &v, sizeof u);
    if constexpr (sizeof(T) == 2)
      u = __builtin_bswap16(u);
    else if constexpr (sizeof(T) == 4)
      u = __builtin_bswap32(u);
    else
      u = __builtin_bswap64(u);
    T r;
    std::memcpy(&r, &u, sizeof r);
    return r;
  }
}

/// Reads a big-endian value from `p`.
template <class T>
T read_big_endian(const char* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  return value_big_endian(v);
}

// Per-format entry points (io_<format>.cpp); mesh_read / mesh_write dispatch to them. The text
// readers parse `text` (the file's bytes) and use `path` only in messages.
HexMesh medit_read(const std::string& path, std::string_view text);
void medit_write(const std::string& path, const HexMesh& mesh);
/// `file`, when `text` is its view: each section's bytes are released once it is read.
HexMesh vtk_read(const std::string& path, std::string_view text, const FileBytes* file = nullptr);
void vtk_write(const std::string& path, const HexMesh& mesh, const bool binary,
               const std::vector<std::pair<std::string, std::vector<double>>>& cell_scalars);
/// `file`, when `text` is its view: large arrays read from it in place are released once copied.
HexMesh vtu_read(const std::string& path, std::string_view text, const FileBytes* file = nullptr);
void vtu_write(const std::string& path, const HexMesh& mesh,
               const std::vector<std::pair<std::string, std::vector<double>>>& cell_scalars,
               bool ascii, bool compress);
/// `file`, when `text` is its view: each section's bytes are released once it is read.
HexMesh gmsh_read(const std::string& path, std::string_view text, const FileBytes* file = nullptr);
void gmsh_write(const std::string& path, const HexMesh& mesh, bool binary,
                const std::vector<std::pair<std::string, std::vector<double>>>& cell_scalars);
HexMesh exodus_read(const std::string& path);
void exodus_write(const std::string& path, const HexMesh& mesh,
                  const std::vector<std::pair<std::string, std::vector<double>>>& cell_scalars);
HexMesh abaqus_read(const std::string& path, std::string_view text);
void abaqus_write(const std::string& path, const HexMesh& mesh);

/// The writers' output buffer: numbers are formatted straight into one 1 MiB buffer with
/// std::to_chars (no std::string per number, no locale, no printf parsing) and the buffer goes
/// to the stream whenever fewer than `item_max` bytes are free, so the stream sees one write
/// per MiB. Every append makes room for itself, so callers need no size bookkeeping.
///
/// Reals are written in the shortest form that reads back as the same double (std::to_chars
/// without a precision: "0.1", "1e-300", "-0", "5e-324", "1.7976931348623157e+308"), so ASCII
/// files stay exact and are shorter than with 17 significant digits.
///
/// Call flush() once at the end; the destructor does not write (a failed write must surface as
/// an exception inside file_write_atomically, not be swallowed by a destructor).
class TextWriter {
 public:
  static constexpr size_t capacity = size_t{1} << 20;
  /// Longer than any one number: a shortest double is at most 24 characters
  /// ("-2.2250738585072014e-308"), an int64 at most 20.
  static constexpr size_t item_max = 64;

  explicit TextWriter(std::ostream& out)
      : out_(out),
        buffer_(new char[capacity]),
        pos_(buffer_.get()),
        end_(buffer_.get() + capacity) {}
  TextWriter(const TextWriter&) = delete;
  TextWriter& operator=(const TextWriter&) = delete;

  /// Shortest round-trip decimal form of a finite double (mesh_write refuses NaN and infinity).
  TextWriter& real(double v) {
    room();
    pos_ = std::to_chars(pos_, end_, v).ptr;
    return *this;
  }
  TextWriter& integer(int64_t v) {
    room();
    pos_ = std::to_chars(pos_, end_, v).ptr;
    return *this;
  }
  TextWriter& put(char c) {
    room();
    *pos_++ = c;
    return *this;
  }
  /// Any length (names, headers); long text goes through in pieces.
  TextWriter& text(std::string_view s) {
    while (!s.empty()) {
      room();
      const size_t n = std::min(s.size(), static_cast<size_t>(end_ - pos_));
      std::memcpy(pos_, s.data(), n);
      pos_ += n;
      s.remove_prefix(n);
    }
    return *this;
  }
  /// `count` values in big-endian byte order, converted straight into the buffer.
  template <class T>
  TextWriter& big_endian(const T* values, size_t count) {
    while (count > 0) {
      room();
      const size_t n = std::min(count, static_cast<size_t>(end_ - pos_) / sizeof(T));
      for (size_t i = 0; i < n; ++i) {
        const T v = value_big_endian(values[i]);
        std::memcpy(pos_ + i * sizeof(T), &v, sizeof(T));
      }
      pos_ += n * sizeof(T);
      values += n;
      count -= n;
    }
    return *this;
  }
  /// `count` values in the machine's own (little-endian) byte order, copied as they are.
  template <class T>
  TextWriter& native(const T* values, size_t count) {
    static_assert(std::is_trivially_copyable_v<T>);
    return text(std::string_view(reinterpret_cast<const char*>(values), count * sizeof(T)));
  }
  template <class T>
  TextWriter& native(T value) {
    return native(&value, 1);
  }
  /// Hands the buffered bytes to the stream.
  void flush() {
    out_.write(buffer_.get(), static_cast<std::streamsize>(pos_ - buffer_.get()));
    pos_ = buffer_.get();
  }

 private:
  void room() {
    if (static_cast<size_t>(end_ - pos_) < item_max) flush();
  }

  std::ostream& out_;
  std::unique_ptr<char[]> buffer_;
  char* pos_;
  char* end_;
};

}  // namespace hexrefine::io_detail
