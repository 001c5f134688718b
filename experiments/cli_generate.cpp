/// \file
/// `hexrefine generate KIND OUT [options]`: builds one of the mesh/generators.hpp meshes and
/// writes it with mesh_write (format from OUT's extension). Options left out keep the
/// generator's defaults; a value outside its range is an InputError (exit 2) naming it.

#include <iostream>

#include "experiments/cli.hpp"
#include "experiments/cli_output.hpp"
#include "mesh/error.hpp"
#include "mesh/generators.hpp"
#include "mesh/io.hpp"

namespace hexrefine {

namespace {

const char* generate_usage =
    "usage: hexrefine generate KIND OUT [options]\n"
    "  brick OUT --dims NX,NY,NZ [--size LX,LY,LZ] [--jitter F --seed S]\n"
    "      NX x NY x NZ hexes over [0,LX]x[0,LY]x[0,LZ] (size default 1,1,1); interior nodes\n"
    "      jittered by up to F (0 <= F < 0.5, default 0) of the spacing, seed S (default 1)\n"
    "  gear OUT [--teeth N] [--radii INNER,ROOT,TIP] [--thickness T] [--layers L]\n"
    "      [--intervals BODY_RADIAL,TOOTH_RADIAL,TOOTH_TANGENTIAL,GAP_TANGENTIAL]\n"
    "      [--tip-fraction F]\n"
    "      defaults: 24 teeth, radii 0.5,1,1.25, thickness 0.3, 7 layers, intervals 7,3,3,3,\n"
    "      tip fraction 0.6 (8,568 hexes); block_id 1 = body, 2 = teeth\n"
    "  cylinder OUT [--radius R] [--height H] [--intervals N,M] [--layers L] [--core C]\n"
    "      O-grid: N x N square (half-side C*R, 0 < C < 0.7) + 4 blocks of N x M;\n"
    "      defaults R 1, H 1, intervals 4,3, 4 layers, core 0.45\n"
    "  twisted-ring OUT [--radius R] [--section S] [--around K] [--section-intervals M]\n"
    "      K >= 8 layers of M x M hexes, section turning a quarter turn around the ring;\n"
    "      defaults R 1, S 0.5 (< R), K 16, M 1 (one self-intersecting sheet)\n"
    "  stepped OUT [--steps S] [--step-layers L] [--depth D] [--top-width W] [--tread T]\n"
    "      [--cell H]\n"
    "      staircase with its risers on the right (x-max); defaults 3,3,12,9,2, cell 1\n"
    "      (1,188 hexes, the thesis' Table 6-1 model)\n";

// Writes `mesh` to `path` and reports the counts on stdout.
int generate_write(const std::string& path, const HexMesh& mesh) {
  mesh_write(path, mesh);
  std::cout << "wrote " << path << ": " << mesh.hex_count() << " hexes, " << mesh.point_count()
            << " nodes\n";
  return 0;
}

// The single integer of option `name`, if given.
void option_int(const CliArgs& a, const std::string& name, int& out) {
  if (const auto v = a.value(name)) out = cli_parse_ints(*v, 1, name)[0];
}

void option_double(const CliArgs& a, const std::string& name, double& out) {
  if (const auto v = a.value(name)) out = cli_parse_double(*v, name);
}

}  // namespace

int cli_generate(const std::vector<std::string>& args) {
  if (args.empty() || args[0] == "--help" || args[0] == "-h") {
    std::cout << generate_usage;
    return args.empty() ? 2 : 0;
  }
  const std::string kind = args[0];
  const std::vector<std::string> rest(args.begin() + 1, args.end());
  auto out_path = [&](const CliArgs& a) {
    if (a.positional.size() != 1)
      throw InputError("hexrefine generate " + kind + ": expected one output path, got " +
                       std::to_string(a.positional.size()) + " positional arguments\n" +
                       generate_usage);
    cli_output_check("hexrefine generate " + kind, a.positional[0], CliOutputKind::mesh);
    return a.positional[0];
  };

  if (kind == "brick") {
    const CliArgs a =
        cli_parse("generate brick", rest, {"--dims", "--size", "--jitter", "--seed"}, {});
    const std::string out = out_path(a);
    BrickParams p;
    const auto dims = a.value("--dims");
    if (!dims) throw InputError("hexrefine generate brick: --dims NX,NY,NZ is required");
    const std::vector<int> d = cli_parse_ints(*dims, 3, "--dims");
    p.dims = {d[0], d[1], d[2]};
    if (const auto v = a.value("--size")) {
      const std::vector<double> s = cli_parse_doubles(*v, 3, "--size");
      p.size = {s[0], s[1], s[2]};
    }
    option_double(a, "--jitter", p.jitter);
    if (const auto v = a.value("--seed")) {
      const long long seed = cli_parse_int(*v, "--seed");
      if (seed < 0) throw InputError("--seed: expected an integer >= 0, got '" + *v + "'");
      p.seed = static_cast<uint64_t>(seed);
    }
    return generate_write(out, generate_brick(p));
  }
  if (kind == "gear") {
    const CliArgs a = cli_parse(
        "generate gear", rest,
        {"--teeth", "--radii", "--thickness", "--layers", "--intervals", "--tip-fraction"}, {});
    const std::string out = out_path(a);
    GearParams p;
    option_int(a, "--teeth", p.teeth);
    if (const auto v = a.value("--radii")) {
      const std::vector<double> r = cli_parse_doubles(*v, 3, "--radii");
      p.inner_radius = r[0];
      p.root_radius = r[1];
      p.tip_radius = r[2];
    }
    option_double(a, "--thickness", p.thickness);
    option_int(a, "--layers", p.layers);
    if (const auto v = a.value("--intervals")) {
      const std::vector<int> n = cli_parse_ints(*v, 4, "--intervals");
      p.body_radial = n[0];
      p.tooth_radial = n[1];
      p.tooth_tangential = n[2];
      p.gap_tangential = n[3];
    }
    option_double(a, "--tip-fraction", p.tip_fraction);
    return generate_write(out, generate_gear(p));
  }
  if (kind == "cylinder") {
    const CliArgs a = cli_parse("generate cylinder", rest,
                                {"--radius", "--height", "--intervals", "--layers", "--core"}, {});
    const std::string out = out_path(a);
    CylinderParams p;
    option_double(a, "--radius", p.radius);
    option_double(a, "--height", p.height);
    if (const auto v = a.value("--intervals")) {
      const std::vector<int> n = cli_parse_ints(*v, 2, "--intervals");
      p.square_intervals = n[0];
      p.radial_intervals = n[1];
    }
    option_int(a, "--layers", p.layers);
    option_double(a, "--core", p.core);
    return generate_write(out, generate_cylinder(p));
  }
  if (kind == "twisted-ring") {
    const CliArgs a = cli_parse("generate twisted-ring", rest,
                                {"--radius", "--section", "--around", "--section-intervals"}, {});
    const std::string out = out_path(a);
    TwistedRingParams p;
    option_double(a, "--radius", p.ring_radius);
    option_double(a, "--section", p.section_size);
    option_int(a, "--around", p.around);
    option_int(a, "--section-intervals", p.section_intervals);
    return generate_write(out, generate_twisted_ring(p));
  }
  if (kind == "stepped") {
    const CliArgs a =
        cli_parse("generate stepped", rest,
                  {"--steps", "--step-layers", "--depth", "--top-width", "--tread", "--cell"}, {});
    const std::string out = out_path(a);
    SteppedParams p;
    option_int(a, "--steps", p.steps);
    option_int(a, "--step-layers", p.step_layers);
    option_int(a, "--depth", p.depth);
    option_int(a, "--top-width", p.top_width);
    option_int(a, "--tread", p.tread);
    option_double(a, "--cell", p.cell);
    return generate_write(out, generate_stepped(p));
  }
  throw InputError("hexrefine generate: unknown kind '" + kind +
                   "' (expected brick, gear, cylinder, twisted-ring or stepped)\n" +
                   generate_usage);
}

}  // namespace hexrefine
