/// `hexrefine sheets MESH [--report R.json]`: the dual sheets and chords of a mesh.
#include <algorithm>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "experiments/cli/cli.hpp"
#include "mesh/atomic_file.hpp"
#include "mesh/dual.hpp"
#include "mesh/error.hpp"
#include "mesh/io.hpp"
#include "mesh/topology.hpp"

namespace hexrefine {

namespace {

// Distinct hex counts listed one per line up to this many; beyond it only min/median/max.
constexpr size_t max_listed_counts = 12;

std::string sheets_summary(const std::string& path, const HexMesh& mesh, const HexTopology& t,
                           const DualSheets& d) {
  int self_intersecting = 0, closed = 0, closed_chords = 0;
  std::map<int32_t, int32_t> sheets_by_hex_count;
  std::vector<int32_t> counts;
  for (const SheetInfo& s : d.sheets) {
    self_intersecting += s.self_intersecting;
    closed += s.closed;
    ++sheets_by_hex_count[s.hex_count];
    counts.push_back(s.hex_count);
  }
  for (const ChordInfo& c : d.chords) closed_chords += c.closed;
  std::ostringstream out;
  out << "mesh: " << path << " (" << mesh.hex_count() << " hexes, " << mesh.point_count()
      << " nodes, " << t.edge_count() << " edges, " << t.face_count() << " faces)\n";
  if (!t.nonmanifold_faces.empty())
    out << "warning: " << t.nonmanifold_faces.size()
        << " faces are shared by more than two hexes (first: face " << t.nonmanifold_faces[0]
        << "); chords through them follow only the first two\n";
  out << "sheets: " << d.sheet_count() << " (self-intersecting " << self_intersecting << ", closed "
      << closed << ")\n";
  if (!counts.empty()) {
    std::sort(counts.begin(), counts.end());
    out << "sheet hex counts: min " << counts.front() << ", median " << counts[counts.size() / 2]
        << ", max " << counts.back() << "\n";
    if (sheets_by_hex_count.size() <= max_listed_counts)
      for (const auto& [hexes, sheets] : sheets_by_hex_count)
        out << "  " << sheets << (sheets == 1 ? " sheet" : " sheets") << " of " << hexes
            << (hexes == 1 ? " hex" : " hexes") << "\n";
  }
  out << "chords: " << d.chord_count() << " (closed " << closed_chords << ")\n";
  return out.str();
}

nlohmann::ordered_json sheets_report(const std::string& path, const HexMesh& mesh,
                                     const DualSheets& d) {
  int self_intersecting = 0, closed = 0, closed_chords = 0;
  nlohmann::ordered_json per_sheet = nlohmann::ordered_json::array();
  for (const SheetInfo& s : d.sheets) {
    self_intersecting += s.self_intersecting;
    closed += s.closed;
    per_sheet.push_back({{"hexes", s.hex_count},
                         {"edges", s.edge_count},
                         {"self_intersecting", s.self_intersecting},
                         {"closed", s.closed}});
  }
  for (const ChordInfo& c : d.chords) closed_chords += c.closed;
  return {{"mesh", path},
          {"hexes", mesh.hex_count()},
          {"nodes", mesh.point_count()},
          {"sheets", d.sheet_count()},
          {"self_intersecting_sheets", self_intersecting},
          {"closed_sheets", closed},
          {"chords", d.chord_count()},
          {"closed_chords", closed_chords},
          {"per_sheet", std::move(per_sheet)}};
}

}  // namespace

namespace {

int sheets_run(const CliArgs& a) {
  if (a.positional.size() != 1)
    throw InputError(
        "hexrefine sheets: expected one mesh file (usage: hexrefine sheets MESH "
        "[--report R.json])");
  const std::string& path = a.positional[0];
  const HexMesh mesh = mesh_read(path);
  mesh_validate_ids(mesh, path);
  const HexTopology topology = topology_build(mesh);
  const DualSheets dual = dual_build(mesh, topology);
  std::cout << sheets_summary(path, mesh, topology, dual);
  if (const auto report = a.value("--report")) {
    const std::string text = sheets_report(path, mesh, dual).dump(2) + "\n";
    file_write_atomically(*report, [&](std::ostream& out) { out << text; });
    std::cout << "report: " << *report << "\n";
  }
  return 0;
}

}  // namespace

const CliCommand cli_sheets_command = {
    "sheets",
    "MESH",
    "Lists the dual sheets (twist planes) and chords of a mesh.",
    {
        {"--report", "R.json", "write every sheet and chord count as JSON"},
    },
    "",
    sheets_run,
};

}  // namespace hexrefine
