#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <fstream>
#include <iterator>

#include "cli_runner.hpp"
#include "io_test_support.hpp"
#include "mesh/error.hpp"
#include "mesh/io.hpp"

namespace hexrefine {
namespace {

MeshWriteOptions io_options_with_scalar(const HexMesh& m, bool binary) {
  MeshWriteOptions o;
  o.binary = binary;
  std::vector<double> q(m.hexes.size());
  for (size_t h = 0; h < q.size(); ++h) q[h] = 1.0 / (1.0 + static_cast<double>(h));
  o.cell_scalars.emplace_back("scaled_jacobian", q);
  return o;
}

TEST(IoVtk, AsciiRoundTripKeepsEverything) {
  const auto dir = test_temp_dir("io_vtk_ascii");
  const HexMesh m = io_test_brick();
  const std::string path = (dir / "brick.vtk").string();
  mesh_write(path, m, io_options_with_scalar(m, false));
  const HexMesh r = mesh_read(path);
  io_expect_same_geometry(m, r, 1e-12);
  io_expect_same_geometry(m, r, 0);
  ASSERT_EQ(r.attributes.size(), 3u);  // the double field is not an integer attribute
  for (const HexAttribute& a : m.attributes) io_expect_same_attribute(m, r, a.name);
}

TEST(IoVtk, BinaryRoundTripIsExact) {
  const auto dir = test_temp_dir("io_vtk_binary");
  const HexMesh m = io_test_brick();
  const std::string path = (dir / "brick.vtk").string();
  mesh_write(path, m, io_options_with_scalar(m, true));
  const HexMesh r = mesh_read(path);
  io_expect_same_geometry(m, r, 0);
  ASSERT_EQ(r.attributes.size(), 3u);
  for (const HexAttribute& a : m.attributes) io_expect_same_attribute(m, r, a.name);
}

TEST(IoVtk, ReadsNewLayoutSkipsQuadsAndReordersVoxels) {
  const auto dir = test_temp_dir("io_vtk_layout");
  const auto p = dir / "mixed.vtk";
  std::string pts;
  for (int i = 0; i < 12; ++i)
    pts += std::to_string(i % 3) + " " + std::to_string((i / 3) % 2) + " " + std::to_string(i / 6) +
           "\n";
  // Voxel order of the cube with corners 0,1,3,4 (bottom) 6,7,9,10 (top): x fastest, then y.
  io_write_text(p,
                "# vtk DataFile Version 5.1\nt\nASCII\nDATASET UNSTRUCTURED_GRID\n"
                "POINTS 12 float\n" +
                    pts +
                    "CELLS 4 20\nOFFSETS vtktypeint64\n0 8 12 20\nCONNECTIVITY vtktypeint64\n"
                    "0 1 4 3 6 7 10 9\n0 1 4 3\n1 2 4 5 7 8 10 11\n"
                    "CELL_TYPES 3\n12\n9\n11\n"
                    "CELL_DATA 3\nFIELD FieldData 2\nblock_id 1 3 int\n5 6 7\n"
                    "quality 1 3 double\n0.5 nan 1\n");
  const HexMesh r = mesh_read(p.string());
  ASSERT_EQ(r.hex_count(), 2);
  EXPECT_EQ(r.hexes[0], (HexCell{0, 1, 4, 3, 6, 7, 10, 9}));
  EXPECT_EQ(r.hexes[1], (HexCell{1, 2, 5, 4, 7, 8, 11, 10}));
  ASSERT_NE(mesh_find_attribute(r, attribute_block_id), nullptr);
  EXPECT_EQ(*mesh_find_attribute(r, attribute_block_id), (std::vector<int32_t>{5, 7}));
}

TEST(IoVtk, ReadsBinaryClassicLayoutSkipsQuadsAndReordersVoxels) {
  // The same three cells as above in the classic layout, BINARY (big-endian): the reader walks
  // the cell list where it lies in the file, keeping only the eight-node cells' ids.
  const auto dir = test_temp_dir("io_vtk_binary_layout");
  const auto p = dir / "mixed.vtk";
  auto be32 = [](int32_t v) {
    std::string b(4, '\0');
    for (int k = 0; k < 4; ++k) b[k] = static_cast<char>(static_cast<uint32_t>(v) >> (24 - 8 * k));
    return b;
  };
  auto be64 = [](double d) {
    const uint64_t u = std::bit_cast<uint64_t>(d);
    std::string b(8, '\0');
    for (int k = 0; k < 8; ++k) b[k] = static_cast<char>(u >> (56 - 8 * k));
    return b;
  };
  std::string text =
      "# vtk DataFile Version 3.0\nt\nBINARY\nDATASET UNSTRUCTURED_GRID\n"
      "POINTS 12 double\n";
  for (int i = 0; i < 12; ++i) text += be64(i % 3) + be64((i / 3) % 2) + be64(i / 6);
  text += "\nCELLS 3 23\n";
  for (int32_t v : {8, 0, 1, 4, 3, 6, 7, 10, 9, 4, 0, 1, 4, 3, 8, 1, 2, 4, 5, 7, 8, 10, 11})
    text += be32(v);
  text += "\nCELL_TYPES 3\n" + be32(12) + be32(9) + be32(11);
  text += "\nCELL_DATA 3\nSCALARS block_id int 1\nLOOKUP_TABLE default\n" + be32(5) + be32(6) +
          be32(7) + "\n";
  io_write_text(p, text);
  const HexMesh r = mesh_read(p.string());
  ASSERT_EQ(r.hex_count(), 2);
  ASSERT_EQ(r.point_count(), 12);
  EXPECT_EQ(r.points[11], Eigen::Vector3d(2, 1, 1));
  EXPECT_EQ(r.hexes[0], (HexCell{0, 1, 4, 3, 6, 7, 10, 9}));
  EXPECT_EQ(r.hexes[1], (HexCell{1, 2, 5, 4, 7, 8, 11, 10}));
  ASSERT_NE(mesh_find_attribute(r, attribute_block_id), nullptr);
  EXPECT_EQ(*mesh_find_attribute(r, attribute_block_id), (std::vector<int32_t>{5, 7}));
  // A node count past the end of the list is refused, naming the cell.
  std::string bad = text;
  bad.replace(bad.find("CELLS 3 23\n") + 11, 4, be32(30));
  io_write_text(dir / "bad.vtk", bad);
  try {
    mesh_read((dir / "bad.vtk").string());
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cell 0 claims 30 nodes"), std::string::npos) << e.what();
  }
}

TEST(IoVtk, RefusesTetraAndBadPointIds) {
  const auto dir = test_temp_dir("io_vtk_bad");
  const std::string head =
      "# vtk DataFile Version 3.0\nt\nASCII\nDATASET UNSTRUCTURED_GRID\n"
      "POINTS 8 double\n0 0 0 1 0 0 1 1 0 0 1 0 0 0 1 1 0 1 1 1 1 0 1 1\n";
  const std::pair<std::string, std::string> cases[] = {
      {head + "CELLS 1 5\n4 0 1 2 4\nCELL_TYPES 1\n10\n",
       "volume cell that is not a linear hexahedron"},
      {head + "CELLS 1 9\n8 0 1 2 3 4 5 6 8\nCELL_TYPES 1\n12\n", "refers to point 8"},
      {head + "CELLS 1 9\n8 0 1 2 3 4 5 6 7\nCELL_TYPES 2\n12\n12\n",
       "differs from the CELLS count"},
      {head + "CELLS 1 9\n8 0 1 2 3 4 5 6\n", "cell list size 9 is more than the rest"},
      {head + "CELLS 1000000000000 9\n", "cell count 1000000000000 exceeds"},
      {head + "CELLS 100000 900000\n8 0 1 2 3 4 5 6 7\n", "more than the rest of the file"},
      {"# vtk DataFile Version 3.0\nt\nASCII\nDATASET STRUCTURED_POINTS\n", "UNSTRUCTURED_GRID"},
  };
  io_expect_refusals(dir, ".vtk", cases);
}

TEST(IoVtu, RoundTripKeepsEverythingInEachEncoding) {
  const auto dir = test_temp_dir("io_vtu");
  const HexMesh m = io_test_brick();
  for (int encoding = 0; encoding < 3; ++encoding) {
    SCOPED_TRACE(encoding);
    const std::string path = (dir / ("brick" + std::to_string(encoding) + ".vtu")).string();
    MeshWriteOptions o = io_options_with_scalar(m, false);
    o.ascii = encoding == 1;
    o.compress = encoding == 2;
    mesh_write(path, m, o);
    std::ifstream in(path, std::ios::binary);
    const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    EXPECT_EQ(text.find("format=\"appended\"") != std::string::npos, encoding != 1);
    EXPECT_EQ(text.find("vtkZLibDataCompressor") != std::string::npos, encoding == 2);
    const HexMesh r = mesh_read(path);
    io_expect_same_geometry(m, r, 0);
    ASSERT_EQ(r.attributes.size(), 3u);
    for (const HexAttribute& a : m.attributes) io_expect_same_attribute(m, r, a.name);
  }
}

TEST(IoVtu, ReadsVtkStyleAsciiWithInformationKeysAndRefusesCorruptBinary) {
  // The layout vtkXMLUnstructuredGridWriter produces in ascii mode: empty PointData, CellData
  // before Points, an InformationKey element inside the Points array.
  const auto dir = test_temp_dir("io_vtu_vtk_style");
  const std::string head =
      "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\">\n"
      "<UnstructuredGrid>\n<Piece NumberOfPoints=\"8\" NumberOfCells=\"1\">\n<PointData>\n"
      "<DataArray type=\"Float32\" Name=\"t\" format=\"ascii\">1 2 3 4 5 6 7 8</DataArray>\n"
      "</PointData>\n<CellData>\n<DataArray type=\"Int32\" Name=\"block_id\" format=\"ascii\">\n"
      "4\n</DataArray>\n</CellData>\n<Points>\n<DataArray type=\"Float64\" Name=\"Points\" "
      "NumberOfComponents=\"3\" format=\"";
  const std::string tail =
      "\">\n0 0 0 1 0 0\n0 1 0 1 1 0\n0 0 1 1 0 1\n0 1 1 1 1 1\n"
      "<InformationKey name=\"L2_NORM_RANGE\" location=\"vtkDataArray\" length=\"2\">\n"
      "<Value index=\"0\">\n0\n</Value>\n</InformationKey>\n</DataArray>\n</Points>\n<Cells>\n"
      "<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n0 1 3 2 4 5\n7 6\n"
      "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" "
      "format=\"ascii\">\n8\n</DataArray>\n"
      "<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n12\n</DataArray>\n</Cells>\n"
      "</Piece>\n</UnstructuredGrid>\n</VTKFile>\n";
  const auto p = dir / "vtk_style.vtu";
  io_write_text(p, head + "ascii" + tail);
  const HexMesh m = mesh_read(p.string());
  ASSERT_EQ(m.hex_count(), 1);
  EXPECT_EQ(m.hexes[0], (HexCell{0, 1, 3, 2, 4, 5, 7, 6}));
  EXPECT_EQ(m.points[7], Eigen::Vector3d(1, 1, 1));
  EXPECT_EQ(*mesh_find_attribute(m, attribute_block_id), std::vector<int32_t>{4});
  const auto q = dir / "binary.vtu";
  io_write_text(q, head + "binary" + tail);
  try {
    mesh_read(q.string());
    FAIL() << "text decoded as base64 accepted";
  } catch (const InputError& e) {
    // The digits are base64 characters: the header decodes to an absurd size.
    EXPECT_NE(std::string(e.what()).find("binary.vtu: byte "), std::string::npos) << e.what();
  }
  // A point id beyond Int32 is refused where it is read (connectivity is held as Int32).
  std::string wide = head + "ascii" + tail;
  const std::string ids = "0 1 3 2 4 5\n7 6";
  wide.replace(wide.find(ids), ids.size(), "0 1 3 2 4 5\n7 5000000000");
  const auto w = dir / "wide.vtu";
  io_write_text(w, wide);
  try {
    mesh_read(w.string());
    FAIL() << "point id 5000000000 accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("'connectivity' holds 5000000000, out of range"),
              std::string::npos)
        << e.what();
  }
}

TEST(IoFormat, ByExtension) {
  EXPECT_EQ(mesh_format_of("a/b.mesh"), MeshFormat::medit);
  EXPECT_EQ(mesh_format_of("b.VTK"), MeshFormat::vtk_legacy);
  EXPECT_EQ(mesh_format_of("b.vtu"), MeshFormat::vtu);
  EXPECT_EQ(mesh_format_of("b.msh"), MeshFormat::gmsh);
  EXPECT_EQ(mesh_format_of("b.e"), MeshFormat::exodus);
  EXPECT_EQ(mesh_format_of("b.exo"), MeshFormat::exodus);
  EXPECT_EQ(mesh_format_of("b.inp"), MeshFormat::abaqus);
  EXPECT_THROW(mesh_format_of("b.stl"), InputError);
  EXPECT_THROW(mesh_format_of("dir.vtk/b"), InputError);
  EXPECT_THROW(mesh_read("/nonexistent/x.vtk"), InputError);
  const auto dir = test_temp_dir("io_format_folder");
  std::filesystem::create_directories(dir / "folder.mesh");
  try {
    mesh_read((dir / "folder.mesh").string());
    ADD_FAILURE() << "folder accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("folder.mesh: is a folder"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace hexrefine
