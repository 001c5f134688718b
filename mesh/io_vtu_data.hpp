#pragma once
/// \file
/// The binary encodings of a VTK XML DataArray (what ParaView, VTK and meshio write besides
/// format="ascii"), for io_vtk.cpp's VTU reader and writer:
/// - a block = header + data. Uncompressed: the header is one integer, the data's byte count.
///   With compressor="vtkZLibDataCompressor": the header is [number of blocks, block size, size
///   of the last block (0: a full block), compressed size of each block], then the blocks, each
///   a zlib stream of at most `block size` bytes. Header integers are UInt32 or UInt64 (the
///   file's header_type), little-endian (byte_order="LittleEndian"; BigEndian is refused).
/// - format="appended" with <AppendedData encoding="raw">: the blocks as bytes after the '_'
///   marker, each DataArray's `offset` counted from just after it.
/// - format="binary" (inline) and appended encoding="base64": each block in base64, the header
///   and the data encoded either separately (VTK, meshio) or as one stream; both are read.

#include <cstdint>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

namespace hexrefine::io_detail {

struct VtuBlockFormat {
  int header_bytes = 8;  ///< 4 (UInt32) or 8 (UInt64)
  bool zlib = false;     ///< vtkZLibDataCompressor
};

/// The data bytes of the raw block at the start of `bytes`; `consumed` receives the block's
/// length. InputError "path: byte N: ..." (N = `file_offset` + the offset of the defect) if the
/// block is truncated, a size is absurd or a zlib stream does not inflate to its size.
/// The data bytes of an uncompressed raw block (precondition: !format.zlib) as a view into
/// `bytes`, not copied; checks and `consumed` as vtu_block_decode_raw.
std::string_view vtu_block_raw_data(std::string_view bytes, const VtuBlockFormat& format,
                                    const std::string& path, size_t file_offset, size_t* consumed);
std::string vtu_block_decode_raw(std::string_view bytes, const VtuBlockFormat& format,
                                 const std::string& path, size_t file_offset, size_t* consumed);

/// The data bytes of a base64-encoded block (white space ignored). Errors as above, at
/// `file_offset` (the text's start).
std::string vtu_block_decode_base64(std::string_view text, const VtuBlockFormat& format,
                                    const std::string& path, size_t file_offset);

/// Length in characters of the base64 block at the start of `text` (no white space inside), so
/// that consecutive blocks of appended base64 data can be told apart.
size_t vtu_block_base64_length(std::string_view text, const VtuBlockFormat& format,
                               const std::string& path, size_t file_offset);

/// The raw block (UInt64 header) of `size` data bytes, compressed in zlib blocks of
/// vtu_zlib_block_size bytes: its length must be known before the XML that gives the offsets.
std::string vtu_block_compress(const void* data, size_t size);

/// Block size of the writer's zlib compression (VTK's default is 32 KiB; larger blocks compress
/// a little better and cost nothing to readers).
inline constexpr size_t vtu_zlib_block_size = size_t{1} << 20;

/// Base64 with '=' padding (RFC 4648), for tests and writers of inline data.
std::string base64_encode(std::string_view bytes);

}  // namespace hexrefine::io_detail
