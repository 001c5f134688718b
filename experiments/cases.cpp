#include "experiments/cases.hpp"

#include <vector>

namespace hexrefine {

namespace {

using nlohmann::json;

json brick(int n, int m, int k) {
  return json{{"generate", "brick"}, {"dims", {n, m, k}}, {"size", {1.0, 1.0, 1.0}}};
}

json make_case(const std::string& name, json mesh, std::vector<std::string> select, json tags) {
  return json{{"name", name},
              {"mesh", std::move(mesh)},
              {"select", std::move(select)},
              {"methods", {"selective", "sheet"}},
              {"tags", std::move(tags)}};
}

}  // namespace

std::vector<int> thesis_sweep_intervals(bool quick) {
  std::vector<int> out;
  for (int n = 5; n <= (quick ? 30 : 75); n += 5) out.push_back(n);
  return out;
}

json thesis_suite_cases(bool quick, const std::string& meshes_dir, const std::string& output) {
  const std::vector<std::string> l_shape = {"boundary:-1,0,0", "boundary:0,0,-1"};
  const std::string corner_ball = "sphere:1,0,1,0.5";
  json cases = json::array();

  // The small ones keep their refined meshes for experiments/render_mesh.py.
  json g1 = make_case("G-1", brick(10, 10, 10), l_shape, {{"table", "G-1"}});
  g1["save_mesh"] = true;
  cases.push_back(g1);
  json stepped =
      make_case("6-1", json{{"generate", "stepped"}}, {"boundary:1,0,0"}, {{"table", "6-1"}});
  stepped["save_mesh"] = true;
  cases.push_back(stepped);
  json piston = make_case("6-2", json{{"file", meshes_dir + "/ellipsoid.mesh"}},
                          {"boundary:0,0,1,45"}, {{"table", "6-2"}});
  piston["smooth"] = true;
  cases.push_back(piston);
  json gear = make_case("H-1", json{{"generate", "gear"}}, {"block:2"}, {{"table", "H-1"}});
  gear["smooth"] = true;
  cases.push_back(gear);
  for (const bool buffer : {true, false}) {
    json c = make_case(buffer ? "H-2" : "H-2/no-buffer", brick(4, 4, 4), {"boundary:-1,0,0"},
                       {{"table", "H-2"}, {"buffer", buffer}});
    c["passes"] = 3;
    c["options"] = {{"buffer", buffer}};
    cases.push_back(c);
  }
  cases.push_back(make_case("H-3",
                            json{{"file", meshes_dir + "/cube_minus_sphere_conforming.mesh"}},
                            {"sphere:0.275,0.275,0,0.15"}, {{"table", "H-3"}}));
  cases.push_back(make_case("H-4", json{{"file", meshes_dir + "/rockerarm.mesh"}}, {"all"},
                            {{"table", "H-4"}}));
  cases.push_back(make_case("real/ellipsoid-sphere", json{{"file", meshes_dir + "/ellipsoid.mesh"}},
                            {"sphere:0,0,0,0.15"}, {{"table", "real"}}));

  // Ablations of the Selective Approach on the L-shaped and the radial case.
  const json variants = {{"no-ranking", {{"ranking", false}}},
                         {"no-propagation", {{"propagation", false}}},
                         {"ebe-only", {{"ebe_only", true}}}};
  for (const auto& [base, mesh, select] :
       {std::tuple{std::string("G-1"), brick(10, 10, 10), l_shape},
        std::tuple{std::string("G-3/n=20"), brick(20, 20, 20),
                   std::vector<std::string>{corner_ball}}}) {
    for (const auto& [variant, options] : variants.items()) {
      json c = make_case("ablation/" + base + "/" + variant, mesh, select,
                         {{"table", "ablation"}, {"base", base}, {"variant", variant}});
      c["methods"] = {"selective"};
      c["options"] = options;
      cases.push_back(c);
    }
  }

  // The sweeps last: they are the long part, and a quick look at the tables above comes first.
  for (const int n : thesis_sweep_intervals(quick))
    cases.push_back(make_case("G-2/n=" + std::to_string(n), brick(n, n, n), {"all"},
                              {{"table", "G-2"}, {"n", n}}));
  for (const int n : thesis_sweep_intervals(quick))
    cases.push_back(make_case("G-3/n=" + std::to_string(n), brick(n, n, n), {corner_ball},
                              {{"table", "G-3"}, {"n", n}}));

  return json{{"description", std::string("Parrish's thesis suite (hexrefine reproduce") +
                                  (quick ? " --quick" : "") + "); see results/README.md"},
              {"cases", cases},
              {"output", output}};
}

}  // namespace hexrefine
