#include "mesh/io_exodus_guard.hpp"

#include <exodusII.h>

#include <cstdint>
#include <cstring>
#include <string>

#include "mesh/error.hpp"
#include "mesh/io_text.hpp"

namespace hexrefine::io_detail {

namespace {

bool netcdf_type_is_number(nc_type type) {
  return type != NC_CHAR && type >= NC_BYTE && type <= NC_UINT64 && type != NC_STRING;
}

}  // namespace

std::optional<NetcdfClassicLayout> netcdf_classic_layout(const std::string& path,
                                                         std::string_view bytes,
                                                         int64_t file_size) {
  const int version = bytes[3];
  const size_t count_size = version == 5 ? 8 : 4;  // NON_NEG: nelems, lengths, dimids
  size_t pos = 4;
  bool truncated = false;
  auto fail = [&](const std::string& what) {
    throw InputError(path + ": not a valid netCDF header (" + what + " at byte " +
                     std::to_string(pos) + ")");
  };
  auto need = [&](uint64_t n) {
    if (n > bytes.size() - pos) {
      if (static_cast<int64_t>(bytes.size()) < file_size) truncated = true;
      return false;
    }
    return true;
  };
  auto number = [&](size_t size, const char* what) -> uint64_t {
    if (!need(size)) {
      if (truncated) return 0;
      fail(std::string("file ends inside ") + what);
    }
    uint64_t v = 0;
    for (size_t i = 0; i < size; ++i) v = (v << 8) | static_cast<unsigned char>(bytes[pos + i]);
    pos += size;
    return v;
  };
  // A count of items needing at least `min_each` bytes each in what is left of the file.
  auto count = [&](const char* what, uint64_t min_each) -> uint64_t {
    const uint64_t n = number(count_size, what);
    if (truncated) return 0;
    if (count_size == 4 && n > INT32_MAX) fail(std::string("negative ") + what);
    if (n > static_cast<uint64_t>(file_size - static_cast<int64_t>(pos)) / min_each)
      fail(std::string(what) + " " + std::to_string(n) + " larger than the file can hold");
    return n;
  };
  auto skip_padded = [&](uint64_t n, const char* what) {
    const uint64_t padded = (n + 3) / 4 * 4;
    if (padded > static_cast<uint64_t>(file_size - static_cast<int64_t>(pos)))
      fail(std::string(what) + " of " + std::to_string(n) + " bytes larger than the file");
    if (!need(padded)) return;
    pos += static_cast<size_t>(padded);
  };
  auto name = [&]() -> std::string {
    const uint64_t n = count("name length", 1);
    if (truncated) return {};
    if (n > 4096) fail("name of " + std::to_string(n) + " bytes");
    const size_t at = pos;
    skip_padded(n, "name");
    return truncated ? std::string() : std::string(bytes.substr(at, static_cast<size_t>(n)));
  };
  auto type_size = [&](uint64_t type) -> uint64_t {
    switch (type) {
      case 1:
      case 2:
      case 7:
        return 1;  // byte, char, ubyte
      case 3:
      case 8:
        return 2;  // short, ushort
      case 4:
      case 5:
      case 9:
        return 4;  // int, float, uint
      case 6:
      case 10:
      case 11:
        return 8;  // double, int64, uint64
    }
    fail("unknown data type " + std::to_string(type));
    return 1;  // not reached: fail throws
  };
  auto attributes = [&] {
    const uint64_t tag = number(4, "attribute list tag");
    const uint64_t n = count("attribute count", 12);
    if (truncated) return;
    if (tag != 0x0C && !(tag == 0 && n == 0)) fail("bad attribute list tag");
    for (uint64_t i = 0; i < n && !truncated; ++i) {
      name();
      const uint64_t type = number(4, "attribute type");
      if (truncated) return;
      const uint64_t size = type_size(type);
      const uint64_t values = count("attribute value count", size);
      if (truncated) return;
      skip_padded(values * size, "attribute values");
    }
  };
  const uint64_t records = number(count_size, "record count");
  // Dimensions.
  const uint64_t dim_tag = number(4, "dimension list tag");
  const uint64_t dims = count("dimension count", 8);
  if (!truncated && dim_tag != 0x0A && !(dim_tag == 0 && dims == 0)) fail("bad dimension list tag");
  std::vector<uint64_t> dim_length;
  for (uint64_t i = 0; i < dims && !truncated; ++i) {
    name();
    dim_length.push_back(number(count_size, "dimension length"));
  }
  if (!truncated) attributes();
  // Variables.
  const uint64_t var_tag = number(4, "variable list tag");
  const uint64_t vars = count("variable count", 24);
  if (!truncated && var_tag != 0x0B && !(var_tag == 0 && vars == 0)) fail("bad variable list tag");
  NetcdfClassicLayout layout;
  layout.version = version;
  layout.records = records;
  for (uint64_t i = 0; i < vars && !truncated; ++i) {
    std::string variable = name();
    const uint64_t rank = count("variable rank", count_size);
    bool record = false;
    for (uint64_t k = 0; k < rank && !truncated; ++k) {
      const uint64_t id = number(count_size, "dimension id");
      if (truncated) break;
      if (id >= dims) fail("dimension id out of range");
      if (k == 0 && dim_length[id] == 0) record = true;  // the unlimited dimension
    }
    if (truncated) break;
    attributes();
    if (truncated) break;
    const uint64_t type = number(4, "variable type");
    type_size(type);
    const uint64_t size = number(count_size, "variable size");
    const uint64_t begin = number(version == 1 ? 4 : 8, "variable offset");
    layout.variables.push_back({std::move(variable), static_cast<int>(type), begin, size, record});
  }
  if (truncated) return std::nullopt;
  return layout;
}

bool netcdf_classic_header_check(const std::string& path, std::string_view bytes,
                                 int64_t file_size) {
  const std::optional<NetcdfClassicLayout> layout = netcdf_classic_layout(path, bytes, file_size);
  if (!layout) return false;
  const uint64_t count_size = layout->version == 5 ? 8 : 4;
  const uint64_t records = layout->records;
  const std::vector<NetcdfVariableExtent>& extents = layout->variables;
  // Every variable's data inside the file: a truncated file is refused here, not read as the
  // netCDF library's zeros or fill values. Record variables repeat every record size bytes.
  uint64_t record_size = 0;
  for (const NetcdfVariableExtent& e : extents)
    if (e.record) record_size += e.size;
  const bool streaming = count_size == 4 && records == 0xFFFFFFFFu;
  for (const NetcdfVariableExtent& e : extents) {
    if (e.size > static_cast<uint64_t>(file_size))
      throw InputError(path + ": netCDF variable of " + std::to_string(e.size) +
                       " bytes larger than the file (" + std::to_string(file_size) + " bytes)");
    uint64_t end = e.begin + e.size;
    if (e.record) {
      if (streaming || records == 0) continue;
      if (record_size > 0 && records - 1 > static_cast<uint64_t>(file_size) / record_size)
        throw InputError(path + ": netCDF record count " + std::to_string(records) +
                         " larger than the file can hold: truncated file");
      end += (records - 1) * record_size;
    }
    if (e.begin > static_cast<uint64_t>(file_size) || end > static_cast<uint64_t>(file_size))
      throw InputError(path + ": netCDF variable data runs past the end of the file (" +
                       std::to_string(file_size) + " bytes): truncated file");
  }
  return true;
}

void exodus_netcdf_check(const std::string& path) {
  NetcdfFile file;
  if (nc_open(path.c_str(), NC_NOWRITE, &file.id) != NC_NOERR) {
    file.id = -1;
    throw InputError(path + ": cannot open as netCDF (corrupt or truncated file)");
  }
  auto attribute_number = [&](const char* name, double& value) {
    nc_type type = NC_NAT;
    size_t length = 0;
    if (nc_inq_att(file.id, NC_GLOBAL, name, &type, &length) != NC_NOERR) return false;
    if (!netcdf_type_is_number(type) || length != 1)
      throw InputError(path + ": global attribute '" + name + "' must be a single number (has " +
                       std::to_string(length) + " values of netCDF type " + std::to_string(type) +
                       ")");
    if (nc_get_att_double(file.id, NC_GLOBAL, name, &value) != NC_NOERR)
      throw InputError(path + ": cannot read global attribute '" + name + "'");
    return true;
  };
  double value = 0;
  for (const char* name :
       {"api_version", "api version", "file_size", "maximum_name_length", "int64_status"})
    attribute_number(name, value);
  if (!attribute_number("version", value) || !(value >= 2.0 && value < 1e6))
    throw InputError(path + ": not an Exodus II file (global attribute 'version' missing or " +
                     "below 2.0)");
  if (!attribute_number("floating_point_word_size", value) &&
      !attribute_number("floating point word size", value))
    throw InputError(path + ": not an Exodus II file (no 'floating_point_word_size' attribute)");
  if (value != 4 && value != 8)
    throw InputError(path + ": floating point word size " + std::to_string(value) +
                     ", expected 4 or 8");
  int variables = 0;
  if (nc_inq_nvars(file.id, &variables) != NC_NOERR)
    throw InputError(path + ": cannot list the netCDF variables");
  char name[NC_MAX_NAME + 1] = {0};
  char dimension[NC_MAX_NAME + 1] = {0};
  for (int v = 0; v < variables; ++v) {
    int rank = 0;
    int dims[NC_MAX_VAR_DIMS] = {0};
    if (nc_inq_varname(file.id, v, name) != NC_NOERR ||
        nc_inq_varndims(file.id, v, &rank) != NC_NOERR || rank < 0 || rank > NC_MAX_VAR_DIMS ||
        nc_inq_vardimid(file.id, v, dims) != NC_NOERR)
      throw InputError(path + ": cannot read netCDF variable " + std::to_string(v));
    nc_type type = NC_NAT;
    size_t length = 0;
    if (nc_inq_att(file.id, v, "elem_type", &type, &length) == NC_NOERR &&
        (type != NC_CHAR || length > MAX_STR_LENGTH))
      throw InputError(path + ": variable '" + name + "': attribute 'elem_type' of " +
                       std::to_string(length) + " values, expected at most " +
                       std::to_string(MAX_STR_LENGTH) + " characters");
    const std::string_view n(name);
    std::vector<std::string> expected;
    if (n == "coordx" || n == "coordy" || n == "coordz")
      expected = {"num_nodes"};
    else if (n == "coord")
      expected = {"num_dim", "num_nodes"};
    else if (n == "eb_prop1")
      expected = {"num_el_blk"};
    else if (n == "elem_num_map")
      expected = {"num_elem"};
    else if (n.substr(0, 7) == "connect") {
      const std::string k(n.substr(7));
      expected = {"num_el_in_blk" + k, "num_nod_per_el" + k};
    } else
      continue;
    bool match = rank == static_cast<int>(expected.size());
    for (int d = 0; match && d < rank; ++d)
      match = nc_inq_dimname(file.id, dims[d], dimension) == NC_NOERR && expected[d] == dimension;
    if (!match) {
      std::string shape;
      for (const std::string& e : expected) shape += (shape.empty() ? "" : ", ") + e;
      throw InputError(path + ": variable '" + name + "' is not defined over (" + shape +
                       "): corrupt Exodus II file");
    }
  }
}

}  // namespace hexrefine::io_detail
