#include "mesh/io_vtu_data.hpp"

#include <zlib.h>

#include <array>
#include <cstring>

#include "mesh/error.hpp"

namespace hexrefine::io_detail {

namespace {

[[noreturn]] void fail_at_byte(const std::string& path, size_t offset, const std::string& what) {
  throw InputError(path + ": byte " + std::to_string(offset) + ": " + what);
}

uint64_t header_integer(std::string_view bytes, size_t at, int header_bytes) {
  if (header_bytes == 4) {
    uint32_t v = 0;
    std::memcpy(&v, bytes.data() + at, 4);
    return v;
  }
  uint64_t v = 0;
  std::memcpy(&v, bytes.data() + at, 8);
  return v;
}

constexpr char base64_alphabet[] =
    "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

constexpr std::array<int8_t, 256> make_base64_values() {
  std::array<int8_t, 256> v{};
  for (size_t i = 0; i < 256; ++i) v[i] = -1;
  for (int i = 0; i < 64; ++i)
    v[static_cast<unsigned char>(base64_alphabet[i])] = static_cast<int8_t>(i);
  return v;
}
constexpr std::array<int8_t, 256> base64_values = make_base64_values();
static_assert(base64_values['A'] == 0 && base64_values['/'] == 63 && base64_values['='] == -1);

/// Base64 text without white space; decodes it whole. InputError at the first bad character.
std::string base64_decode(std::string_view text, const std::string& path, size_t file_offset) {
  if (text.size() % 4 != 0)
    fail_at_byte(path, file_offset + text.size(),
                 "base64 data of " + std::to_string(text.size()) +
                     " characters (not a multiple of 4): truncated or corrupt");
  std::string out;
  out.reserve(text.size() / 4 * 3);
  for (size_t i = 0; i < text.size(); i += 4) {
    uint32_t group = 0;
    int padding = 0;
    for (int k = 0; k < 4; ++k) {
      const char c = text[i + k];
      int v;
      if (c == '=' && k >= 2 && i + 4 == text.size()) {
        ++padding;
        v = 0;
      } else {
        v = base64_values[static_cast<unsigned char>(c)];
        if (v < 0 || padding > 0)
          fail_at_byte(path, file_offset + i + k,
                       std::string("character '") + c + "' is not base64");
      }
      group = (group << 6) | static_cast<uint32_t>(v);
    }
    out.push_back(static_cast<char>(group >> 16));
    if (padding < 2) out.push_back(static_cast<char>((group >> 8) & 0xFF));
    if (padding < 1) out.push_back(static_cast<char>(group & 0xFF));
  }
  return out;
}

/// Inflates the zlib blocks of `data` (after a header of `header_end` bytes in `block`).
std::string inflate_blocks(std::string_view block, const VtuBlockFormat& format,
                           const std::string& path, size_t file_offset, size_t* consumed) {
  const int hb = format.header_bytes;
  if (block.size() < 3 * static_cast<size_t>(hb))
    fail_at_byte(path, file_offset, "compressed block header truncated");
  const uint64_t blocks = header_integer(block, 0, hb);
  const uint64_t block_size = header_integer(block, hb, hb);
  const uint64_t last_size = header_integer(block, 2 * static_cast<size_t>(hb), hb);
  if (blocks > block.size() / static_cast<size_t>(hb) || (blocks > 0 && block_size == 0) ||
      last_size > block_size)
    fail_at_byte(path, file_offset,
                 "compressed block header claims " + std::to_string(blocks) + " blocks of " +
                     std::to_string(block_size) + " bytes: more than the file holds");
  const size_t header_end = (3 + static_cast<size_t>(blocks)) * static_cast<size_t>(hb);
  if (header_end > block.size())
    fail_at_byte(path, file_offset, "compressed block header truncated");
  uint64_t total = 0;
  size_t at = header_end;
  for (uint64_t b = 0; b < blocks; ++b) {
    const uint64_t c = header_integer(block, (3 + static_cast<size_t>(b)) * hb, hb);
    if (c > block.size() - at)
      fail_at_byte(path, file_offset + at,
                   "compressed block " + std::to_string(b) + " of " + std::to_string(c) +
                       " bytes is truncated");
    at += static_cast<size_t>(c);
    total += b + 1 == blocks && last_size > 0 ? last_size : block_size;
  }
  // A zlib stream inflates to at most about 1032 times its size: larger claims are corrupt.
  if (total > 1100 * static_cast<uint64_t>(at) + 1024)
    fail_at_byte(path, file_offset,
                 "compressed block claims " + std::to_string(total) +
                     " bytes, more than its streams can hold");
  std::string out(static_cast<size_t>(total), '\0');
  size_t in_at = header_end, out_at = 0;
  for (uint64_t b = 0; b < blocks; ++b) {
    const uint64_t c = header_integer(block, (3 + static_cast<size_t>(b)) * hb, hb);
    const uint64_t expect = b + 1 == blocks && last_size > 0 ? last_size : block_size;
    uLongf produced = static_cast<uLongf>(expect);
    const int status =
        uncompress(reinterpret_cast<Bytef*>(out.data() + out_at), &produced,
                   reinterpret_cast<const Bytef*>(block.data() + in_at), static_cast<uLong>(c));
    if (status != Z_OK || produced != expect)
      fail_at_byte(path, file_offset + in_at,
                   "zlib block " + std::to_string(b) + " does not inflate to " +
                       std::to_string(expect) + " bytes (corrupt data)");
    in_at += static_cast<size_t>(c);
    out_at += static_cast<size_t>(expect);
  }
  if (consumed) *consumed = in_at;
  return out;
}

std::string without_white_space(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text)
    if (c != ' ' && c != '\n' && c != '\r' && c != '\t') out.push_back(c);
  return out;
}

}  // namespace

std::string vtu_block_decode_raw(std::string_view bytes, const VtuBlockFormat& format,
                                 const std::string& path, size_t file_offset, size_t* consumed) {
  if (format.zlib) return inflate_blocks(bytes, format, path, file_offset, consumed);
  return std::string(vtu_block_raw_data(bytes, format, path, file_offset, consumed));
}

std::string_view vtu_block_raw_data(std::string_view bytes, const VtuBlockFormat& format,
                                    const std::string& path, size_t file_offset, size_t* consumed) {
  const size_t hb = static_cast<size_t>(format.header_bytes);
  if (bytes.size() < hb) fail_at_byte(path, file_offset, "block header truncated");
  const uint64_t size = header_integer(bytes, 0, format.header_bytes);
  if (size > bytes.size() - hb)
    fail_at_byte(path, file_offset,
                 "block of " + std::to_string(size) + " bytes, but only " +
                     std::to_string(bytes.size() - hb) + " follow");
  if (consumed) *consumed = hb + static_cast<size_t>(size);
  return bytes.substr(hb, static_cast<size_t>(size));
}

namespace {

/// The header of a base64 block: its decoded bytes and whether header and data are encoded
/// separately (the header's last group padded).
struct Base64Header {
  std::string bytes;   ///< exactly the header's bytes
  size_t encoded = 0;  ///< characters of the header's own encoding
  bool separate = false;
};

Base64Header base64_header(std::string_view clean, const VtuBlockFormat& format,
                           const std::string& path, size_t file_offset) {
  const size_t hb = static_cast<size_t>(format.header_bytes);
  // The header's byte count: one integer, or (3 + blocks) integers when compressed; the
  // number of blocks comes from the first group(s) of the text either way.
  size_t header_size = hb;
  if (format.zlib) {
    const size_t first = 4 * ((hb + 2) / 3);
    if (clean.size() < first) fail_at_byte(path, file_offset, "base64 block header truncated");
    const std::string head = base64_decode(clean.substr(0, first), path, file_offset);
    const uint64_t blocks = header_integer(head, 0, format.header_bytes);
    if (blocks > clean.size()) fail_at_byte(path, file_offset, "compressed block header corrupt");
    header_size = (3 + static_cast<size_t>(blocks)) * hb;
  }
  Base64Header h;
  h.encoded = 4 * ((header_size + 2) / 3);
  if (clean.size() < h.encoded) fail_at_byte(path, file_offset, "base64 block header truncated");
  // Encoded alone, the header ends in exactly the padding its length gives (2 '=' for 4 bytes,
  // 1 for 8); a block encoded in one stream has data (or other padding) there.
  const size_t padding = (3 - header_size % 3) % 3;
  size_t found = 0;
  while (found < 2 && clean[h.encoded - 1 - found] == '=') ++found;
  h.separate = padding > 0 && found == padding;
  h.bytes = base64_decode(clean.substr(0, h.encoded), path, file_offset);
  h.bytes.resize(header_size);
  return h;
}

/// Bytes of data a block header announces (the sum of the compressed sizes with zlib).
uint64_t block_data_bytes(const std::string& header, const VtuBlockFormat& format) {
  const int hb = format.header_bytes;
  if (!format.zlib) return header_integer(header, 0, hb);
  uint64_t total = 0;
  for (size_t at = 3 * static_cast<size_t>(hb); at < header.size(); at += hb)
    total += header_integer(header, at, hb);
  return total;
}

}  // namespace

size_t vtu_block_base64_length(std::string_view text, const VtuBlockFormat& format,
                               const std::string& path, size_t file_offset) {
  const Base64Header h = base64_header(text, format, path, file_offset);
  const uint64_t data = block_data_bytes(h.bytes, format);
  if (data > text.size()) fail_at_byte(path, file_offset, "base64 block larger than the file");
  const size_t length = h.separate ? h.encoded + 4 * ((static_cast<size_t>(data) + 2) / 3)
                                   : 4 * ((h.bytes.size() + static_cast<size_t>(data) + 2) / 3);
  if (length > text.size())
    fail_at_byte(path, file_offset,
                 "base64 block of " + std::to_string(length) +
                     " characters, but the data ends after " + std::to_string(text.size()));
  return length;
}

std::string vtu_block_decode_base64(std::string_view text, const VtuBlockFormat& format,
                                    const std::string& path, size_t file_offset) {
  const std::string clean = without_white_space(text);
  const Base64Header h = base64_header(clean, format, path, file_offset);
  std::string block;
  if (h.separate) {
    // Header and data encoded separately (VTK, meshio).
    block = h.bytes +
            base64_decode(std::string_view(clean).substr(h.encoded), path, file_offset + h.encoded);
  } else {
    block = base64_decode(clean, path, file_offset);
  }
  return vtu_block_decode_raw(block, format, path, file_offset, nullptr);
}

std::string vtu_block_compress(const void* data, size_t size) {
  const size_t blocks = (size + vtu_zlib_block_size - 1) / vtu_zlib_block_size;
  std::vector<uint64_t> header = {blocks, vtu_zlib_block_size, size % vtu_zlib_block_size};
  std::string body;
  std::string buffer(compressBound(static_cast<uLong>(vtu_zlib_block_size)), '\0');
  const char* in = static_cast<const char*>(data);
  for (size_t b = 0; b < blocks; ++b) {
    const size_t n = std::min(vtu_zlib_block_size, size - b * vtu_zlib_block_size);
    uLongf produced = static_cast<uLongf>(buffer.size());
    // Level 1: most of the size reduction at a fraction of the default level's time.
    if (compress2(reinterpret_cast<Bytef*>(buffer.data()), &produced,
                  reinterpret_cast<const Bytef*>(in + b * vtu_zlib_block_size),
                  static_cast<uLong>(n), 1) != Z_OK)
      throw OperationError("zlib compression failed");
    header.push_back(produced);
    body.append(buffer.data(), produced);
  }
  std::string out(header.size() * 8, '\0');
  std::memcpy(out.data(), header.data(), out.size());
  return out + body;
}

std::string base64_encode(std::string_view bytes) {
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (size_t i = 0; i < bytes.size(); i += 3) {
    const size_t n = std::min<size_t>(3, bytes.size() - i);
    uint32_t group = 0;
    for (size_t k = 0; k < 3; ++k)
      group = (group << 8) | (k < n ? static_cast<unsigned char>(bytes[i + k]) : 0u);
    for (size_t k = 0; k < 4; ++k)
      out.push_back(k <= n ? base64_alphabet[(group >> (18 - 6 * k)) & 63] : '=');
  }
  return out;
}

}  // namespace hexrefine::io_detail
