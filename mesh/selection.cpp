/// Target selection (see selection.hpp for the SPEC forms). Each spec marks hexes in one flag
/// array; the result is read off the flags in ascending order, so uniting is linear and the
/// output is sorted and unique without a sort.
#include "mesh/selection.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <numbers>
#include <random>
#include <sstream>

#include "mesh/boundary_surface.hpp"
#include "mesh/error.hpp"

namespace hexrefine {

namespace {

std::string spec_error(const std::string& spec, const std::string& message) {
  return "--select '" + spec + "': " + message;
}

double parse_number(const std::string& text, const std::string& spec) {
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size() || errno == ERANGE || !std::isfinite(v))
    throw InputError(spec_error(spec, "expected a finite number, got '" + text + "'"));
  return v;
}

// Comma-separated numbers; their count must be one of `counts`.
std::vector<double> parse_numbers(const std::string& text, const std::string& spec,
                                  std::initializer_list<size_t> counts) {
  std::vector<double> out;
  size_t start = 0;
  while (true) {
    const size_t comma = text.find(',', start);
    out.push_back(parse_number(text.substr(start, comma - start), spec));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  for (size_t c : counts)
    if (out.size() == c) return out;
  std::string expected;
  for (size_t c : counts) expected += (expected.empty() ? "" : " or ") + std::to_string(c);
  throw InputError(spec_error(spec, "expected " + expected + " comma-separated numbers, got " +
                                        std::to_string(out.size())));
}

// Parses a whole token as a base-10 integer; false if it is not one or overflows int64.
bool parse_integer(const std::string& token, long long& value) {
  errno = 0;
  char* end = nullptr;
  value = std::strtoll(token.c_str(), &end, 10);
  return !token.empty() && end == token.c_str() + token.size() && errno != ERANGE;
}

void select_from_file(const std::string& file, int32_t hex_count, const std::string& spec,
                      std::vector<char>& selected) {
  if (file.empty()) throw InputError(spec_error(spec, "expected a file name after 'hexes:'"));
  std::ifstream in(file);
  if (!in) throw InputError(error_at(file, 0, "cannot open the hex id file (" + spec + ")"));
  std::string line;
  int64_t line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    const size_t hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    std::istringstream tokens(line);
    std::string token;
    while (tokens >> token) {
      long long id = 0;
      if (!parse_integer(token, id))
        throw InputError(error_at(file, line_number, "expected a hex id, got '" + token + "'"));
      if (id < 0 || id >= hex_count)
        throw InputError(
            error_at(file, line_number,
                     "hex id " + token + " out of range [0, " + std::to_string(hex_count) + ")"));
      selected[id] = 1;
    }
  }
  if (in.bad()) throw InputError(error_at(file, line_number, "read error"));
}

}  // namespace

Selection select_hexes(const HexMesh& mesh, const HexTopology& t,
                       const std::vector<std::string>& specs) {
  const int32_t nh = mesh.hex_count();
  std::vector<char> selected(nh, 0);
  for (const std::string& spec : specs) {
    const size_t colon = spec.find(':');
    const std::string kind = spec.substr(0, colon);
    const std::string rest = colon == std::string::npos ? std::string() : spec.substr(colon + 1);
    if (kind == "all") {
      if (colon != std::string::npos) throw InputError(spec_error(spec, "'all' takes no value"));
      std::fill(selected.begin(), selected.end(), 1);
      continue;
    }
    if (colon == std::string::npos)
      throw InputError(spec_error(spec,
                                  "expected all, hexes:FILE, box:..., sphere:..., boundary:..., "
                                  "block:..., random:..., blob:... or surface:..."));
    if (kind == "hexes") {
      select_from_file(rest, nh, spec, selected);
    } else if (kind == "box") {
      const std::vector<double> b = parse_numbers(rest, spec, {6});
      if (b[0] > b[3] || b[1] > b[4] || b[2] > b[5])
        throw InputError(spec_error(spec, "box needs x0 <= x1, y0 <= y1, z0 <= z1"));
      for (int32_t h = 0; h < nh; ++h) {
        const Eigen::Vector3d c = hex_centroid(mesh, h);
        if (c.x() >= b[0] && c.x() <= b[3] && c.y() >= b[1] && c.y() <= b[4] && c.z() >= b[2] &&
            c.z() <= b[5])
          selected[h] = 1;
      }
    } else if (kind == "sphere") {
      const std::vector<double> s = parse_numbers(rest, spec, {4});
      if (s[3] < 0) throw InputError(spec_error(spec, "radius must be >= 0"));
      const Eigen::Vector3d centre(s[0], s[1], s[2]);
      for (int32_t h = 0; h < nh; ++h)
        if ((hex_centroid(mesh, h) - centre).squaredNorm() <= s[3] * s[3]) selected[h] = 1;
    } else if (kind == "boundary") {
      const std::vector<double> v = parse_numbers(rest, spec, {3, 4});
      Eigen::Vector3d direction(v[0], v[1], v[2]);
      if (direction.norm() == 0) throw InputError(spec_error(spec, "direction must be non-zero"));
      direction.normalize();
      const double degrees = v.size() == 4 ? v[3] : 30.0;
      if (degrees < 0 || degrees > 180)
        throw InputError(spec_error(spec, "angle must be in [0, 180] degrees"));
      // A small tolerance so that an exactly aligned face passes at deg = 0.
      const double cos_limit = std::cos(degrees * std::numbers::pi / 180.0) - 1e-12;
      for (int32_t f = 0; f < t.face_count(); ++f) {
        if (!face_is_boundary(t, f)) continue;
        const Eigen::Vector3d n = face_unit_normal(mesh, t, f);
        if (!n.isZero() && n.dot(direction) >= cos_limit) selected[t.face_hexes[f][0]] = 1;
      }
    } else if (kind == "block") {
      const std::vector<int32_t>* block = mesh_find_attribute(mesh, attribute_block_id);
      if (!block) throw InputError(spec_error(spec, "the mesh has no block_id attribute"));
      std::vector<long long> ids;
      std::istringstream items(rest);
      std::string item;
      while (std::getline(items, item, ',')) {
        long long id = 0;
        if (!parse_integer(item, id))
          throw InputError(spec_error(spec, "expected a block id, got '" + item + "'"));
        ids.push_back(id);
      }
      if (ids.empty() || rest.back() == ',')
        throw InputError(spec_error(spec, "expected block ids after 'block:'"));
      for (int32_t h = 0; h < nh; ++h)
        for (long long id : ids)
          if ((*block)[h] == id) selected[h] = 1;
    } else if (kind == "random") {
      const std::vector<double> v = parse_numbers(rest, spec, {2});
      if (!(v[0] > 0 && v[0] <= 1))
        throw InputError(spec_error(spec, "fraction must be in (0, 1]"));
      if (v[1] < 0 || v[1] != std::floor(v[1]) || v[1] > 9.007199254740992e15)
        throw InputError(spec_error(spec, "seed must be an integer >= 0"));
      std::mt19937_64 rng(static_cast<uint64_t>(v[1]));
      for (int32_t h = 0; h < nh; ++h)
        if (static_cast<double>(rng() >> 11) * 0x1.0p-53 < v[0]) selected[h] = 1;
    } else if (kind == "blob") {
      const std::vector<double> v = parse_numbers(rest, spec, {2});
      if (v[0] < 1 || v[0] != std::floor(v[0]))
        throw InputError(spec_error(spec, "count must be an integer >= 1"));
      if (v[1] < 0 || v[1] != std::floor(v[1]) || v[1] > 9.007199254740992e15)
        throw InputError(spec_error(spec, "seed must be an integer >= 0"));
      if (nh == 0) continue;
      std::mt19937_64 rng(static_cast<uint64_t>(v[1]));
      const int32_t start = static_cast<int32_t>(rng() % static_cast<uint64_t>(nh));
      const int64_t wanted = std::min<int64_t>(static_cast<int64_t>(v[0]), nh);
      std::vector<char> in(nh, 0);
      std::vector<int32_t> queue = {start};
      in[start] = 1;
      for (size_t i = 0; i < queue.size() && static_cast<int64_t>(i) < wanted; ++i) {
        selected[queue[i]] = 1;
        for (int lf = 0; lf < 6; ++lf) {
          const int32_t n = hex_face_neighbor(t, queue[i], lf);
          if (n >= 0 && !in[n]) {
            in[n] = 1;
            queue.push_back(n);
          }
        }
      }
    } else if (kind == "surface") {
      const std::vector<double> v = parse_numbers(rest, spec, {1, 2});
      if (v[0] < 0 || v[0] != std::floor(v[0]))
        throw InputError(spec_error(spec, "patch rank must be an integer >= 0"));
      const double degrees = v.size() == 2 ? v[1] : 30.0;
      if (!(degrees > 0 && degrees <= 180))
        throw InputError(spec_error(spec, "feature angle must be in (0, 180] degrees"));
      const BoundarySurface surface = boundary_surface_build(mesh, t);
      const SurfacePatches patches = boundary_surface_patches(surface, degrees);
      // Patches by decreasing face count, ties by patch id: rank 0 is the largest.
      std::vector<int32_t> order(patches.patch_count());
      for (int32_t p = 0; p < patches.patch_count(); ++p) order[p] = p;
      std::stable_sort(order.begin(), order.end(), [&](int32_t a, int32_t b) {
        return patches.patch_face_counts[a] > patches.patch_face_counts[b];
      });
      const size_t rank = static_cast<size_t>(v[0]);
      if (rank >= order.size())
        throw InputError(spec_error(spec, "the boundary has " + std::to_string(order.size()) +
                                              " surfaces at that feature angle"));
      for (int32_t f = 0; f < surface.face_count(); ++f)
        if (patches.face_patch[f] == order[rank]) selected[surface.face_hex[f]] = 1;
    } else {
      throw InputError(spec_error(spec, "unknown selection '" + kind +
                                            "' (expected all, hexes, box, sphere, boundary, "
                                            "block, random, blob or surface)"));
    }
  }

  Selection out;
  for (int32_t h = 0; h < nh; ++h)
    if (selected[h]) out.hexes.push_back(h);
  if (out.hexes.empty()) {
    std::string joined;
    for (const std::string& spec : specs) joined += (joined.empty() ? "'" : ", '") + spec + "'";
    out.warning = specs.empty() ? "no selection given: no hex selected"
                                : "selection " + joined + " matches no hex";
  }
  return out;
}

Selection select_hexes(const HexMesh& mesh, const std::vector<std::string>& specs) {
  bool faces = false;
  for (const std::string& spec : specs)
    for (const char* kind : {"boundary:", "blob:", "surface:"})
      faces = faces || spec.rfind(kind, 0) == 0;
  return select_hexes(mesh, faces ? topology_build(mesh, TopologyParts::faces) : HexTopology{},
                      specs);
}

}  // namespace hexrefine
