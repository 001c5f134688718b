/// \file
/// The generators' parameter table (generators.hpp): the CLI's `generate` and the case files'
/// "mesh" objects both read parameters through it.

#include <algorithm>
#include <cmath>

#include "mesh/error.hpp"
#include "mesh/generators.hpp"

namespace hexrefine {

namespace {

template <class Params, HexMesh (*Build)(const Params&)>
HexMesh generate_from_json(const nlohmann::json& params) {
  return Build(params.get<Params>());
}

template <class Params, HexMesh (*Build)(const Params&)>
Generator generator_make(std::string name, std::string description,
                         std::vector<GeneratorField> fields) {
  Generator g{std::move(name), std::move(description), std::move(fields), Params{},
              generate_from_json<Params, Build>};
  return g;
}

}  // namespace

const std::vector<Generator>& generators() {
  static const std::vector<Generator> table = {
      generator_make<BrickParams, generate_brick>(
          "brick", "an axis-aligned brick of NX x NY x NZ hexes",
          {{"dims", "hexes per axis NX,NY,NZ, each >= 1"},
           {"size", "extent per axis LX,LY,LZ, each > 0"},
           {"jitter", "interior nodes moved by up to this fraction of the spacing, in [0, 0.5)"},
           {"seed", "seed of the jitter, >= 0"}}),
      generator_make<GearParams, generate_gear>(
          "gear", "a toothed annulus extruded along z; block_id 1 = body, 2 = teeth",
          {{"teeth", ">= 3"},
           {"inner_radius", "> 0"},
           {"root_radius", "> inner_radius"},
           {"tip_radius", "> root_radius"},
           {"thickness", "> 0"},
           {"layers", "hex layers through the thickness, >= 1"},
           {"body_radial", "radial intervals of the body, >= 1"},
           {"tooth_radial", "radial intervals of a tooth, >= 1"},
           {"tooth_tangential", "intervals across a tooth, >= 1"},
           {"gap_tangential", "intervals across a gap, >= 1"},
           {"tip_fraction", "tip width / root width, in (0, 1]"}}),
      generator_make<CylinderParams, generate_cylinder>(
          "cylinder", "an O-grid cylinder about the z-axis",
          {{"radius", "> 0"},
           {"height", "> 0"},
           {"square_intervals", "intervals of the central square, >= 1"},
           {"radial_intervals", "intervals from the square to the circle, >= 1"},
           {"layers", ">= 1"},
           {"core", "half-side of the square / radius, in (0, 0.7)"}}),
      generator_make<TwistedRingParams, generate_twisted_ring>(
          "twisted-ring",
          "a ring whose square section turns a quarter turn (self-intersecting sheets)",
          {{"ring_radius", "> 0"},
           {"section_size", "in (0, ring_radius)"},
           {"around", "hex layers around the ring, >= 8"},
           {"section_intervals", "hexes across the section, >= 1"}}),
      generator_make<SteppedParams, generate_stepped>(
          "stepped", "a staircase with its risers on x-max (the thesis' Table 6-1 model)",
          {{"steps", ">= 1"},
           {"step_layers", "hex layers per step, >= 1"},
           {"depth", "hexes along y, >= 1"},
           {"top_width", "hexes along x of the top step, >= 1"},
           {"tread", "extra hexes along x per lower step, >= 1"},
           {"cell", "hex edge length, > 0"}}),
  };
  return table;
}

const Generator& generator_find(std::string_view name) {
  std::string known;
  for (const Generator& g : generators()) {
    if (g.name == name || (name == "twisted_ring" && g.name == "twisted-ring")) return g;
    known += (known.empty() ? "" : ", ") + g.name;
  }
  throw InputError("unknown generator '" + std::string(name) + "' (expected one of: " + known +
                   ")");
}

nlohmann::json generator_params(const Generator& g, const nlohmann::json& given,
                                const std::string& where) {
  if (!given.is_object()) throw InputError(where + ": expected an object of parameters");
  nlohmann::json out = g.defaults;
  for (const auto& [key, value] : given.items()) {
    const std::string at = where + "/" + key;
    if (!g.defaults.contains(key)) {
      std::string list;
      for (const GeneratorField& f : g.fields) list += (list.empty() ? "" : ", ") + f.name;
      throw InputError(at + ": unknown parameter of generator '" + g.name +
                       "' (expected one of: " + list + ")");
    }
    const nlohmann::json& d = g.defaults[key];
    auto kind_ok = [](const nlohmann::json& def, const nlohmann::json& v) {
      if (def.is_number_unsigned())
        return v.is_number_unsigned() || (v.is_number_integer() && v.get<int64_t>() >= 0);
      if (def.is_number_integer()) return v.is_number_integer();
      return v.is_number() && std::isfinite(v.get<double>());
    };
    const char* expected = d.is_number_unsigned()                     ? "an integer >= 0"
                           : d.is_number_integer()                    ? "an integer"
                           : d.is_array() && d[0].is_number_integer() ? "3 integers"
                           : d.is_array()                             ? "3 numbers"
                                                                      : "a finite number";
    bool ok = true;
    if (d.is_array()) {
      ok = value.is_array() && value.size() == d.size();
      for (size_t i = 0; ok && i < d.size(); ++i) ok = kind_ok(d[i], value[i]);
    } else {
      ok = kind_ok(d, value);
    }
    if (!ok) throw InputError(at + ": expected " + expected + ", got " + value.dump());
    out[key] = value;
  }
  return out;
}

}  // namespace hexrefine
