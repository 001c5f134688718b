/// \file
/// `hexrefine convert IN OUT [--binary]`: reads IN and writes OUT, formats chosen by extension
/// (mesh/io.hpp). Attributes travel where the output format can hold them. For .vtk and .vtu
/// outputs the per-hex scaled Jacobian is added as the cell field "scaled_jacobian", so a viewer
/// shows the quality without another tool. --binary selects BINARY VTK legacy or binary Gmsh 4.1
/// output and is refused for every other output format (it would be silently ignored otherwise).

#include <iostream>

#include "experiments/cli/cli.hpp"
#include "experiments/cli/cli_output.hpp"
#include "mesh/error.hpp"
#include "mesh/io.hpp"
#include "mesh/quality.hpp"

namespace hexrefine {

namespace {

int convert_run(const CliArgs& a) {
  if (a.positional.size() != 2)
    throw InputError("hexrefine convert: expected IN OUT (two paths), got " +
                     std::to_string(a.positional.size()) + " arguments");
  const std::string& in = a.positional[0];
  const std::string& out = a.positional[1];
  const MeshFormat out_format = mesh_format_of(out);
  mesh_format_of(in);
  cli_output_check("hexrefine convert", out, CliOutputKind::mesh);
  MeshWriteOptions options = cli_mesh_write_options(a, "hexrefine convert", out);
  const HexMesh mesh = mesh_read(in);
  if (out_format == MeshFormat::vtk_legacy || out_format == MeshFormat::vtu)
    options.cell_scalars.emplace_back("scaled_jacobian", mesh_scaled_jacobians(mesh));
  mesh_write(out, mesh, options);
  std::cout << "converted " << in << " -> " << out << ": " << mesh.point_count() << " nodes, "
            << mesh.hex_count() << " hexes\n";
  return 0;
}

}  // namespace

const CliCommand cli_convert_command = {
    "convert",
    "IN OUT",
    "Converts between mesh formats (by extension: .mesh .vtk .vtu .msh .e/.exo .inp).",
    {
        {"--binary", "", "binary instead of text output (.vtk: BINARY; .msh: Gmsh 4.1 binary)"},
        {"--ascii", "", "VTU output as text instead of appended binary data (.vtu only)"},
        {"--compress", "", "VTU output zlib-compressed (.vtu only)"},
    },
    "",
    convert_run,
};

}  // namespace hexrefine
