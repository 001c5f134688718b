/// \file
/// `hexrefine generate KIND OUT [--PARAMETER VALUE ...]`: builds one of the mesh/generators.hpp
/// meshes and writes it with mesh_write (format from OUT's extension). The options are the
/// generator's parameters (generators(): the same table the case files use), '_' written '-';
/// options left out keep the generator's defaults; a value outside its range is an InputError
/// (exit 2) naming it.

#include <iostream>
#include <sstream>

#include "experiments/cli/cli.hpp"
#include "experiments/cli/cli_output.hpp"
#include "mesh/error.hpp"
#include "mesh/generators.hpp"
#include "mesh/io.hpp"

namespace hexrefine {

namespace {

std::string option_name(const std::string& field) {
  std::string s = "--" + field;
  std::replace(s.begin(), s.end(), '_', '-');
  return s;
}

/// The generator's parameters as options of a command named "generate KIND".
CliCommand generator_command(const Generator& g) {
  CliCommand c{"generate " + g.name, "OUT", g.description, {}, "", nullptr};
  for (const GeneratorField& f : g.fields) {
    const nlohmann::json& d = g.defaults.at(f.name);
    const std::string value = d.is_array() ? "A,B,C" : d.is_number_integer() ? "N" : "X";
    c.options.push_back({option_name(f.name), value, f.help + " (default " + d.dump() + ")"});
  }
  return c;
}

/// The text of option `o` as the JSON value of its field (kind from the default).
nlohmann::json option_value(const nlohmann::json& d, const std::string& text,
                            const std::string& o) {
  if (d.is_array()) {
    if (d[0].is_number_integer()) return cli_parse_ints(text, static_cast<int>(d.size()), o);
    return cli_parse_doubles(text, static_cast<int>(d.size()), o);
  }
  if (d.is_number_unsigned()) {
    const long long v = cli_parse_int(text, o);
    if (v < 0) throw InputError(o + ": expected an integer >= 0, got '" + text + "'");
    return static_cast<uint64_t>(v);
  }
  if (d.is_number_integer()) return cli_parse_ints(text, 1, o)[0];
  return cli_parse_double(text, o);
}

std::string kinds_help() {
  std::ostringstream out;
  out << "kinds (hexrefine generate KIND --help is the same list):\n";
  for (const Generator& g : generators()) {
    out << "  " << g.name << ": " << g.description << "\n";
    for (const GeneratorField& f : g.fields)
      out << "      " << option_name(f.name) << " " << g.defaults.at(f.name).dump() << "  "
          << f.help << "\n";
  }
  return out.str();
}

int generate_run(const CliArgs& raw) {
  if (raw.positional.empty())
    throw InputError("hexrefine generate: expected KIND and OUT (hexrefine generate --help)");
  std::string kind = raw.positional[0];
  const Generator* g = nullptr;
  try {
    g = &generator_find(kind);
  } catch (const InputError& e) {
    throw InputError(std::string("hexrefine generate: unknown kind: ") + e.what());
  }
  const CliCommand command = generator_command(*g);
  const CliArgs a = cli_parse(command, {raw.positional.begin() + 1, raw.positional.end()});
  if (a.positional.size() != 1)
    throw InputError("hexrefine generate " + g->name + ": expected one output path, got " +
                     std::to_string(a.positional.size()) + " positional arguments");
  const std::string out = a.positional[0];
  cli_output_check("hexrefine generate " + g->name, out, CliOutputKind::mesh);
  nlohmann::json given = nlohmann::json::object();
  for (const GeneratorField& f : g->fields)
    if (const auto v = a.value(option_name(f.name)))
      given[f.name] = option_value(g->defaults.at(f.name), *v, option_name(f.name));
  const HexMesh mesh = g->generate(generator_params(*g, given, "hexrefine generate " + g->name));
  mesh_write(out, mesh);
  std::cout << "wrote " << out << ": " << mesh.hex_count() << " hexes, " << mesh.point_count()
            << " nodes\n";
  return 0;
}

}  // namespace

const CliCommand cli_generate_command = {
    "generate",
    "KIND OUT [--PARAMETER VALUE ...]",
    "Builds a generated mesh (brick, gear, cylinder, twisted-ring, stepped) and writes OUT.",
    {},
    "",
    generate_run,
    kinds_help,
    true,
};

}  // namespace hexrefine
