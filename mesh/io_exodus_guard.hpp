#pragma once
/// \file
/// What an Exodus II file must satisfy before libexodusii and libnetcdf see it: both take their
/// headers on trust (allocations of whatever a header claims, attributes copied into fixed
/// buffers), so the reader checks the classic netCDF header bytes and, through the netCDF API,
/// every attribute and variable shape libexodusii 6.02 relies on (results/fuzzing.md, findings
/// 2, 4 and 5).

#include <netcdf.h>

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace hexrefine::io_detail {

/// Closes a netCDF id on every path out.
struct NetcdfFile {
  int id = -1;
  ~NetcdfFile() {
    if (id >= 0) nc_close(id);
  }
};

/// Where a netCDF classic file keeps one variable's data: its name, netCDF type (NC_INT, ...),
/// offset of its first byte and size in bytes (of one record for a record variable).
struct NetcdfVariableExtent {
  std::string name;
  int type = 0;
  uint64_t begin = 0, size = 0;
  bool record = false;
};

/// The header of a netCDF classic file: format version (1, 2 or 5), record count and the
/// variables in file order.
struct NetcdfClassicLayout {
  int version = 0;
  uint64_t records = 0;
  std::vector<NetcdfVariableExtent> variables;
};

/// Walks the header of a netCDF classic file (see netcdf_classic_header_check, which calls it)
/// and returns its layout; nullopt when the header runs past `bytes` but not past `file_size`.
/// Throws InputError naming `path` when it is malformed.
std::optional<NetcdfClassicLayout> netcdf_classic_layout(const std::string& path,
                                                         std::string_view bytes, int64_t file_size);

/// Walks the header of a netCDF classic file (CDF-1, CDF-2 or CDF-5: magic, record count, then
/// the dimension, global attribute and variable lists, each "tag, count, entries") and checks
/// every count and length against the bytes that follow, so the netCDF library, which allocates
/// whatever its header claims (a name length of 1.4 GB was found by fuzzing), only ever sees
/// headers the file can hold. `bytes` is the start of the file (at least the whole header, or
/// the whole file); returns false when the header runs past `bytes` but not past `file_size`
/// (the caller reads more), throws InputError naming `path` when it is malformed.
bool netcdf_classic_header_check(const std::string& path, std::string_view bytes,
                                 int64_t file_size);

/// Checks, through the netCDF API (classic and HDF5 files alike), what libexodusii 6.02 takes on
/// trust, so that ex_open and the ex_get_* calls of exodus_read only see files they handle:
/// - ex_open fails after its nc_open succeeded when the global attribute `version` is missing,
///   not a number or below 2.0, or when no float word size attribute is found, and then never
///   closes the netCDF file: one file descriptor and the netCDF file's memory leak per refused
///   file (this is what made the Exodus fuzz target die after ~300,000 inputs).
/// - ex_open reads `version`, the float word size and `int64_status` with nc_get_att_*, which
///   writes every value of the attribute into a single float or int: an attribute with several
///   values overwrites the stack (ours for `version`, libexodusii's for the others).
/// - ex_get_block copies the `elem_type` attribute whole into a MAX_STR_LENGTH + 1 buffer.
/// - ex_get_coord, ex_get_ids, ex_get_id_map and ex_get_conn read a whole variable into a buffer
///   sized from the dimensions with the expected names (num_nodes, num_el_blk, num_elem,
///   num_el_in_blkK x num_nod_per_elK), so each variable must be defined over exactly those.
/// Throws InputError naming `path` and the attribute or variable.
void exodus_netcdf_check(const std::string& path);

}  // namespace hexrefine::io_detail
