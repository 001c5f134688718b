/// \file
/// Files that are valid netCDF but break what libexodusii 6.02 takes on trust (see
/// exodus_netcdf_check in mesh/io_exodus.cpp): each is made from a file hexrefine wrote, edited
/// through the netCDF API, and must be refused with an InputError naming the file, without
/// leaving a file descriptor open (ex_open leaked one per refused file before the check; the
/// Exodus fuzz target ran out of them) and without overwriting memory.

#include <gtest/gtest.h>
#include <netcdf.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <string>
#include <vector>

#include "cli_runner.hpp"
#include "io_test_support.hpp"
#include "mesh/error.hpp"
#include "mesh/io.hpp"

namespace hexrefine {
namespace {

/// Number of open file descriptors of this process.
int process_open_files() {
  int n = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator("/proc/self/fd"))
    ++n;
  return n;
}

/// Writes fixture_brick(2, 1, 1) to `path` as Exodus II, then applies `edit` to it in netCDF
/// define mode.
void exodus_write_edited(const std::string& path, const std::function<void(int)>& edit) {
  mesh_write(path, fixture_brick(2, 1, 1));
  int id = -1;
  ASSERT_EQ(nc_open(path.c_str(), NC_WRITE, &id), NC_NOERR);
  ASSERT_EQ(nc_redef(id), NC_NOERR);
  edit(id);
  ASSERT_EQ(nc_close(id), NC_NOERR);
}

struct EditCase {
  std::string name;
  std::function<void(int)> edit;
  std::string message;  // a part of the expected InputError message
};

std::vector<EditCase> exodus_edit_cases() {
  const std::vector<float> floats(300, 6.0f);
  const std::vector<int> ints(300, 8);
  const std::string long_text(200, 'H');
  auto variable = [](int id, const char* name) {
    int v = -1;
    EXPECT_EQ(nc_inq_varid(id, name, &v), NC_NOERR) << name;
    return v;
  };
  return {
      {"no_version", [](int id) { EXPECT_EQ(nc_del_att(id, NC_GLOBAL, "version"), NC_NOERR); },
       "'version' missing"},
      {"old_version",
       [](int id) {
         const float v = 1.5f;
         EXPECT_EQ(nc_put_att_float(id, NC_GLOBAL, "version", NC_FLOAT, 1, &v), NC_NOERR);
       },
       "below 2.0"},
      {"text_version",
       [](int id) { EXPECT_EQ(nc_put_att_text(id, NC_GLOBAL, "version", 4, "6.02"), NC_NOERR); },
       "'version' must be a single number"},
      {"no_word_size",
       [](int id) { EXPECT_EQ(nc_del_att(id, NC_GLOBAL, "floating_point_word_size"), NC_NOERR); },
       "floating_point_word_size"},
      {"word_size_5",
       [](int id) {
         const int five = 5;
         EXPECT_EQ(nc_put_att_int(id, NC_GLOBAL, "floating_point_word_size", NC_INT, 1, &five),
                   NC_NOERR);
       },
       "word size 5"},
      // Each of these overwrote the stack of ex_open or of its caller.
      {"version_300_values",
       [floats](int id) {
         EXPECT_EQ(
             nc_put_att_float(id, NC_GLOBAL, "version", NC_FLOAT, floats.size(), floats.data()),
             NC_NOERR);
       },
       "'version' must be a single number (has 300 values"},
      {"word_size_300_values",
       [ints](int id) {
         EXPECT_EQ(nc_put_att_int(id, NC_GLOBAL, "floating_point_word_size", NC_INT, ints.size(),
                                  ints.data()),
                   NC_NOERR);
       },
       "'floating_point_word_size' must be a single number"},
      {"int64_status_300_values",
       [ints](int id) {
         EXPECT_EQ(nc_put_att_int(id, NC_GLOBAL, "int64_status", NC_INT, ints.size(), ints.data()),
                   NC_NOERR);
       },
       "'int64_status' must be a single number"},
      // ex_get_block copied this into a 33-byte buffer.
      {"long_elem_type",
       [long_text, variable](int id) {
         EXPECT_EQ(nc_put_att_text(id, variable(id, "connect1"), "elem_type", long_text.size(),
                                   long_text.data()),
                   NC_NOERR);
       },
       "'elem_type' of 200 values"},
      // Swapped dimension names: libexodusii would size the coordinate buffers from num_nodes
      // (now 3) and read coordx whole (12 values) into them.
      {"swapped_dimensions",
       [](int id) {
         int nodes = -1, dim = -1;
         EXPECT_EQ(nc_inq_dimid(id, "num_nodes", &nodes), NC_NOERR);
         EXPECT_EQ(nc_inq_dimid(id, "num_dim", &dim), NC_NOERR);
         EXPECT_EQ(nc_rename_dim(id, nodes, "tmp_nodes"), NC_NOERR);
         EXPECT_EQ(nc_rename_dim(id, dim, "num_nodes"), NC_NOERR);
         EXPECT_EQ(nc_rename_dim(id, nodes, "num_dim"), NC_NOERR);
       },
       "is not defined over (num_nodes)"},
      // The same for the connectivity: num_el_in_blk1 (2) and num_nod_per_el1 (8) swapped keep
      // the size, so rename the element count to a new dimension instead.
      {"connectivity_dimension",
       [](int id) {
         int d = -1;
         EXPECT_EQ(nc_inq_dimid(id, "num_el_in_blk1", &d), NC_NOERR);
         EXPECT_EQ(nc_rename_dim(id, d, "num_el_in_blk9"), NC_NOERR);
       },
       "'connect1' is not defined over (num_el_in_blk1, num_nod_per_el1)"},
  };
}

TEST(IoExodusLibraryGuard, UntrustedAttributesAndShapesAreRefusedWithoutLeaks) {
  const auto dir = test_temp_dir("io_exodus_library_guard");
  for (const EditCase& c : exodus_edit_cases()) {
    const std::string path = (dir / (c.name + ".e")).string();
    exodus_write_edited(path, c.edit);
    const int open_before = process_open_files();
    for (int round = 0; round < 20; ++round) {
      try {
        mesh_read(path);
        ADD_FAILURE() << c.name << ": accepted";
      } catch (const InputError& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find(path), std::string::npos) << message;
        EXPECT_NE(message.find(c.message), std::string::npos) << c.name << ": " << message;
      }
    }
    EXPECT_EQ(process_open_files(), open_before) << c.name << ": file descriptors leaked";
  }
}

TEST(IoExodusLibraryGuard, UnchangedFileStillReads) {
  const auto dir = test_temp_dir("io_exodus_library_guard_ok");
  const std::string path = (dir / "ok.e").string();
  exodus_write_edited(path, [](int) {});
  const int open_before = process_open_files();
  const HexMesh m = mesh_read(path);
  EXPECT_EQ(m.hex_count(), 2);
  EXPECT_EQ(m.point_count(), 12);
  EXPECT_EQ(process_open_files(), open_before);
}

/// The in-memory reader (the fuzz targets' path) writes each input to a temporary file: reading
/// many refused inputs in a row must leave neither descriptors nor temporary files behind.
TEST(IoExodusLibraryGuard, RefusedMemoryInputsLeaveNoFilesOrDescriptors) {
  const auto dir = test_temp_dir("io_exodus_library_guard_memory");
  const std::string path = (dir / "no_version.e").string();
  exodus_write_edited(path, exodus_edit_cases()[0].edit);
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // A private temporary folder so that parallel tests and fuzzers cannot disturb the count.
  const auto private_tmp = dir / "tmp";
  std::filesystem::create_directories(private_tmp);
  const char* old_tmpdir = std::getenv("TMPDIR");
  const std::string saved = old_tmpdir ? old_tmpdir : "";
  ::setenv("TMPDIR", private_tmp.c_str(), 1);
  const int open_before = process_open_files();
  for (int round = 0; round < 50; ++round)
    EXPECT_THROW(mesh_read_from_memory("input.e", bytes), InputError);
  const int open_after = process_open_files();
  const auto left = std::distance(std::filesystem::directory_iterator(private_tmp),
                                  std::filesystem::directory_iterator());
  if (old_tmpdir)
    ::setenv("TMPDIR", saved.c_str(), 1);
  else
    ::unsetenv("TMPDIR");
  EXPECT_EQ(open_after, open_before);
  EXPECT_EQ(left, 0);
}

}  // namespace
}  // namespace hexrefine
