#include "experiments/runner/cases.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <cstdio>
#include <vector>

#include "mesh/conformity.hpp"
#include "mesh/io.hpp"

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
              {"options", {{"placement", "trilinear"}}},
              {"tags", std::move(tags)}};
}

/// The same case with optimized placement: the extra column of the single-case tables.
json optimized_variant(json c) {
  c["name"] = c["name"].get<std::string>() + "/optimized";
  c["options"]["placement"] = "optimized";
  c["tags"]["placement"] = "optimized";
  c.erase("save_mesh");
  c.erase("expect");  // optimized placement untangles what the trilinear positions invert
  return c;
}

std::string number_text(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", x);
  return buf;
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

  // The small ones keep their refined meshes for experiments/studies/render_mesh.py.
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
  gear["save_mesh"] = true;
  cases.push_back(gear);
  // A twisted ring (3x3 section: its in-section sheets cross themselves) refined around one
  // place: the self-intersecting sheets the thesis says sheet refinement must special-case.
  json ring = make_case("ring", json{{"generate", "twisted-ring"}, {"section_intervals", 3}},
                        {"sphere:1,0,0,0.6"}, {{"table", "ring"}});
  ring["save_mesh"] = true;
  cases.push_back(ring);
  for (const char* buffer : {"layer", "none", "transitions"}) {
    const std::string name = std::string(buffer) == "layer" ? "H-2" : "H-2/" + std::string(buffer);
    json c = make_case(name, brick(4, 4, 4), {"boundary:-1,0,0"},
                       {{"table", "H-2"}, {"buffer", buffer}});
    c["passes"] = 3;
    c["options"]["buffer"] = buffer;
    cases.push_back(c);
  }
  // With the thesis' trilinear positions the Selective Approach's templates invert 16 children
  // in 8 distorted parents of our stand-in plate: a refusal the suite expects (the record says
  // so, and the summary counts it apart from the errors).
  json plate = make_case("H-3", json{{"file", meshes_dir + "/cube_minus_sphere_conforming.mesh"}},
                         {"sphere:0.275,0.275,0,0.15"}, {{"table", "H-3"}});
  plate["expect"] = {{"selective", "refused"}};
  cases.push_back(plate);
  cases.push_back(make_case("H-4", json{{"file", meshes_dir + "/rockerarm.mesh"}}, {"all"},
                            {{"table", "H-4"}}));
  cases.push_back(make_case("real/ellipsoid-sphere", json{{"file", meshes_dir + "/ellipsoid.mesh"}},
                            {"sphere:0,0,0,0.15"}, {{"table", "real"}}));

  // Every single-case table again with optimized node placement (the thesis' numbers above are
  // the trilinear placement's).
  const size_t single = cases.size();
  for (size_t i = 0; i < single; ++i) cases.push_back(optimized_variant(cases[i]));

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
      c["options"].update(options);
      cases.push_back(c);
    }
  }

  // The sweeps last: they are the long part, and a quick look at the tables above comes first.
  for (const int n : thesis_sweep_intervals(quick))
    cases.push_back(make_case("G-2/n=" + std::to_string(n), brick(n, n, n), {"all"},
                              {{"table", "G-2"}, {"n", n}}));
  for (const int n : thesis_sweep_intervals(quick)) {
    json c = make_case("G-3/n=" + std::to_string(n), brick(n, n, n), {corner_ball},
                       {{"table", "G-3"}, {"n", n}});
    if (n == 10) c["save_mesh"] = true;  // the radial region's picture
    cases.push_back(c);
  }

  return json{{"description", std::string("Parrish's thesis suite (hexrefine reproduce") +
                                  (quick ? " --quick" : "") + "); see results/README.md"},
              {"cases", cases},
              {"output", output}};
}

const std::vector<std::string>& study_arms() {
  static const std::vector<std::string> arms = {"trilinear", "default", "default-smooth"};
  return arms;
}

namespace {

/// `c` set up as `arm` of study_arms(): its placement and smoothing, passes > 1 with the buffer.
json study_arm_case(json c, const std::string& arm, int passes) {
  c["options"] = json::object();
  // No placement given for the default arms: what a user who names none gets, with and without
  // --smooth (the pipeline's default may differ between the two, issue 28 decision 2).
  if (arm == "trilinear") c["options"]["placement"] = "trilinear";
  c["smooth"] = arm == "default-smooth";
  c["tags"]["arm"] = arm;
  if (passes > 1) {
    c["passes"] = passes;
    c["options"]["buffer"] = "layer";
  }
  return c;
}

}  // namespace

json real_mesh_study_cases(const std::vector<StudyMesh>& meshes, const std::string& output,
                           int64_t max_hexes_input, std::vector<std::string>* skipped) {
  json cases = json::array();
  for (const StudyMesh& mesh : meshes) {
    HexMesh m;
    try {
      m = mesh_read(mesh.path);
    } catch (const std::exception& e) {
      // "Every readable mesh": a file that does not read is named, not studied.
      if (skipped) skipped->push_back(mesh.path + ": " + e.what());
      continue;
    }
    if (m.hex_count() > max_hexes_input) {
      if (skipped)
        skipped->push_back(mesh.path + ": " + std::to_string(m.hex_count()) +
                           " hexes, above the limit of " + std::to_string(max_hexes_input));
      continue;
    }
    // The checker's verdict on the input decides whether a refusal is a defect (valid input) or
    // the right answer (invalid input), so the report need not guess it from the message.
    const MeshCheckReport input_check = mesh_check(m);
    json defects = json::array();
    for (const std::string& d : mesh_check_defects(input_check))
      if (defects.size() < 3) defects.push_back(d.substr(0, 200));
    const auto [lo, hi] = mesh_bounding_box(m);
    const Eigen::Vector3d centre = (lo + hi) / 2;
    const double diagonal = (hi - lo).norm();
    auto sphere = [&](double fraction) {
      return "sphere:" + number_text(centre.x()) + "," + number_text(centre.y()) + "," +
             number_text(centre.z()) + "," + number_text(fraction * diagonal);
    };
    const std::string blob_count = std::to_string(std::max<int32_t>(20, m.hex_count() / 50));
    struct Kind {
      std::string name;
      std::vector<std::string> select;
      int passes;
    };
    std::vector<Kind> kinds = {
        {"sphere", {sphere(0.15)}, 1},
        {"blob-1", {"blob:" + blob_count + ",1"}, 1},
        {"blob-2", {"blob:" + blob_count + ",2"}, 1},
        {"surface", {"surface:0"}, 1},
        {"scattered-1", {"random:0.02,1"}, 1},
        {"scattered-2", {"random:0.02,2"}, 1},
        {"two-passes", {sphere(0.1)}, 2},
    };
    // The case of the real-mesh issue: a ball at the rocker arm's origin.
    if (mesh.shared && mesh.file == "rockerarm.mesh")
      kinds.push_back({"issue-sphere", {"sphere:0,0,0,5"}, 1});
    const std::string prefix = mesh.shared ? mesh.file : mesh.folder + ":" + mesh.file;
    for (const Kind& kind : kinds)
      for (const std::string& arm : study_arms()) {
        json c = make_case(prefix + "/" + kind.name + "/" + arm, json{{"file", mesh.case_path}},
                           kind.select,
                           {{"study", "real_meshes"},
                            {"mesh", mesh.file},
                            {"folder", mesh.folder},
                            {"source", mesh.shared ? "shared" : "meshes"},
                            {"kind", kind.name},
                            {"input_valid", input_check.valid()},
                            {"input_defects", defects}});
        cases.push_back(study_arm_case(c, arm, kind.passes));
      }
  }
  // Anisotropic boxes: parents whose scaled Jacobian is 1 but whose edges differ by a factor a,
  // around one target hex in the middle of a 5x5x5 brick (long: boxes 1 x 1 x a, the target's
  // neighbours above and below get a transition template in their small face; flat: a x a x 1).
  for (const double a : {1.0, 1.5, 2.0, 3.0, 4.0})
    for (const char* orientation : {"long", "flat"}) {
      const bool flat = std::string(orientation) == "flat";
      if (a == 1.0 && flat) continue;
      const std::array<double, 3> size = flat ? std::array{a, a, 1.0} : std::array{1.0, 1.0, a};
      const std::string select = "sphere:" + number_text(size[0] / 2) + "," +
                                 number_text(size[1] / 2) + "," + number_text(size[2] / 2) +
                                 ",0.01";
      for (const std::string& arm : study_arms()) {
        json c =
            make_case("aspect-" + number_text(a) + "-" + orientation + "/" + arm,
                      json{{"generate", "brick"}, {"dims", {5, 5, 5}}, {"size", size}}, {select},
                      {{"study", "anisotropy"},
                       {"aspect", a},
                       {"orientation", orientation},
                       {"input_valid", true}});
        cases.push_back(study_arm_case(c, arm, 1));
      }
    }
  return json{{"description",
               "Real-mesh study (hexrefine study): every mesh x region kind x both methods x arm "
               "(trilinear; default placement; default placement with --smooth); and one target "
               "hex among anisotropic boxes; see results/real_meshes.md"},
              {"cases", cases},
              {"output", output}};
}

}  // namespace hexrefine
