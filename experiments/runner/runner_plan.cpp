/// \file
/// The case file of `hexrefine run` (results/README.md, "Running your own cases"): its schema,
/// checked key by key with the file and the JSON path of every bad value, into a RunPlan.

#include <algorithm>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "algorithms/pipeline/pipeline.hpp"
#include "experiments/runner/runner.hpp"
#include "mesh/error.hpp"
#include "mesh/generators.hpp"

namespace hexrefine {

namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

/// Validation context: the file and the JSON path of the value being checked.
struct SchemaPath {
  const std::string& file;
  std::string path;

  SchemaPath at(const std::string& key) const { return {file, path + "/" + key}; }
  SchemaPath at(size_t i) const { return {file, path + "/" + std::to_string(i)}; }
  [[noreturn]] void fail(const std::string& what) const {
    throw InputError(file + ": " + (path.empty() ? "/" : path) + ": " + what);
  }
};

void schema_require_object(const json& j, const SchemaPath& p) {
  if (!j.is_object()) p.fail("expected an object");
}

void schema_allow_keys(const json& j, const SchemaPath& p,
                       std::initializer_list<const char*> keys) {
  for (const auto& [k, v] : j.items()) {
    bool known = false;
    for (const char* key : keys) known = known || k == key;
    if (!known) {
      std::string list;
      for (const char* key : keys) list += std::string(list.empty() ? "" : ", ") + key;
      p.at(k).fail("unknown key (expected one of: " + list + ")");
    }
  }
}

std::string schema_string(const json& j, const SchemaPath& p) {
  if (!j.is_string() || j.get<std::string>().empty()) p.fail("expected a non-empty string");
  return j.get<std::string>();
}

int64_t schema_int(const json& j, const SchemaPath& p, int64_t min_value) {
  if (!j.is_number_integer() || j.get<int64_t>() < min_value)
    p.fail("expected an integer >= " + std::to_string(min_value));
  return j.get<int64_t>();
}

bool schema_bool(const json& j, const SchemaPath& p) {
  if (!j.is_boolean()) p.fail("expected true or false");
  return j.get<bool>();
}

std::vector<std::string> schema_strings(const json& j, const SchemaPath& p) {
  if (!j.is_array() || j.empty()) p.fail("expected a non-empty array of strings");
  std::vector<std::string> out;
  for (size_t i = 0; i < j.size(); ++i) out.push_back(schema_string(j[i], p.at(i)));
  return out;
}

json parse_mesh(const json& j, const SchemaPath& p, const std::string& base_dir) {
  schema_require_object(j, p);
  const bool has_file = j.contains("file");
  const bool has_generate = j.contains("generate");
  if (has_file == has_generate) p.fail("expected exactly one of \"generate\" or \"file\"");
  if (has_file) {
    schema_allow_keys(j, p, {"file"});
    const std::string given = schema_string(j["file"], p.at("file"));
    fs::path path(given);
    if (path.is_relative()) path = fs::path(base_dir) / path;
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) p.at("file").fail("mesh file not found: " + path.string());
    return json{{"file", given}, {"path", path.lexically_normal().string()}};
  }
  const std::string kind = schema_string(j["generate"], p.at("generate"));
  const Generator* generator = nullptr;
  try {
    generator = &generator_find(kind);
  } catch (const InputError& e) {
    p.at("generate").fail(e.what());
  }
  json given = j;
  given.erase("generate");
  json out = generator_params(*generator, given, p.file + ": " + (p.path.empty() ? "" : p.path));
  out["generate"] = generator->name;
  return out;
}

RunCase parse_case(const json& j, const SchemaPath& p, const std::string& base_dir, int index) {
  schema_require_object(j, p);
  schema_allow_keys(j, p,
                    {"name", "description", "mesh", "select", "methods", "passes", "smooth",
                     "save_mesh", "options", "expect", "tags"});
  RunCase c;
  c.index = index;
  if (!j.contains("name")) p.fail("missing \"name\"");
  c.name = schema_string(j["name"], p.at("name"));
  if (!j.contains("mesh")) p.fail("missing \"mesh\"");
  c.mesh = parse_mesh(j["mesh"], p.at("mesh"), base_dir);
  if (!j.contains("select")) p.fail("missing \"select\" (use [\"all\"] to refine every hex)");
  c.select_given = schema_strings(j["select"], p.at("select"));
  for (const std::string& spec : c.select_given) {
    if (spec.compare(0, 6, "hexes:") == 0 && fs::path(spec.substr(6)).is_relative())
      c.select.push_back("hexes:" +
                         (fs::path(base_dir) / spec.substr(6)).lexically_normal().string());
    else
      c.select.push_back(spec);
  }
  c.methods = {"selective", "sheet"};
  if (j.contains("methods")) {
    c.methods = schema_strings(j["methods"], p.at("methods"));
    std::set<std::string> seen;
    for (size_t i = 0; i < c.methods.size(); ++i) {
      try {
        refine_method(c.methods[i]);
      } catch (const InputError& e) {
        p.at("methods").at(i).fail(e.what());
      }
      if (!seen.insert(c.methods[i]).second)
        p.at("methods").at(i).fail("method '" + c.methods[i] + "' listed twice");
    }
  }
  if (j.contains("passes")) {
    const int64_t passes = schema_int(j["passes"], p.at("passes"), 1);
    if (passes > 10) p.at("passes").fail("expected an integer in [1, 10]");
    c.options.passes = static_cast<int>(passes);
  }
  if (j.contains("smooth")) c.smooth = schema_bool(j["smooth"], p.at("smooth"));
  if (j.contains("save_mesh")) c.save_mesh = schema_bool(j["save_mesh"], p.at("save_mesh"));
  if (j.contains("options")) {
    const json& o = j["options"];
    const SchemaPath op = p.at("options");
    schema_require_object(o, op);
    schema_allow_keys(o, op,
                      {"ranking", "directional_order", "propagation", "ebe_only", "buffer",
                       "allow_inverted", "placement"});
    if (o.contains("ranking")) c.options.ranking = schema_bool(o["ranking"], op.at("ranking"));
    if (o.contains("directional_order")) {
      const std::string order = schema_string(o["directional_order"], op.at("directional_order"));
      if (order != "by_rank" && order != "by_hex")
        op.at("directional_order")
            .fail("expected \"by_rank\" or \"by_hex\", got \"" + order + "\"");
      c.options.directional_order =
          order == "by_hex" ? DirectionalOrder::by_hex : DirectionalOrder::by_rank;
    }
    if (o.contains("propagation"))
      c.options.propagation = schema_bool(o["propagation"], op.at("propagation"));
    if (o.contains("ebe_only")) c.options.ebe_only = schema_bool(o["ebe_only"], op.at("ebe_only"));
    if (o.contains("buffer")) {
      // A rule name; the booleans of earlier case files mean what they meant then.
      if (o["buffer"].is_boolean())
        c.options.buffer = o["buffer"].get<bool>() ? PassBuffer::transitions : PassBuffer::none;
      else
        try {
          c.options.buffer = pass_buffer_from_name(schema_string(o["buffer"], op.at("buffer")));
        } catch (const InputError& e) {
          op.at("buffer").fail(e.what());
        }
    }
    if (o.contains("allow_inverted"))
      c.options.allow_inverted = schema_bool(o["allow_inverted"], op.at("allow_inverted"));
    if (o.contains("placement")) {
      const std::string placement = schema_string(o["placement"], op.at("placement"));
      if (placement == "trilinear")
        c.options.placement.method = PlacementMethod::trilinear;
      else if (placement == "optimized")
        c.options.placement.method = PlacementMethod::optimized;
      else if (placement == "untangle")
        c.options.placement.method = PlacementMethod::untangle;
      else if (placement == "reference")
        c.options.placement.method = PlacementMethod::reference;
      else
        op.at("placement")
            .fail("expected \"trilinear\", \"reference\", \"optimized\" or \"untangle\"");
    }
  }
  if (!j.contains("options") || !j["options"].contains("placement"))
    c.options.placement.method = pipeline_default_placement(c.smooth);
  if (j.contains("expect")) {
    // "refused" for every method of the case, or {"METHOD": "refused", ...} for listed methods.
    const json& e = j["expect"];
    const SchemaPath ep = p.at("expect");
    auto expect_value = [](const json& v, const SchemaPath& vp) {
      if (!v.is_string() || v.get<std::string>() != "refused")
        vp.fail("expected \"refused\" (the only expectation a case can state)");
    };
    if (e.is_object()) {
      if (e.empty()) ep.fail("expected \"refused\" or an object {\"METHOD\": \"refused\"}");
      for (const auto& [method, value] : e.items()) {
        if (std::find(c.methods.begin(), c.methods.end(), method) == c.methods.end())
          ep.at(method).fail("method '" + method + "' is not one of the case's methods");
        expect_value(value, ep.at(method));
        c.refusals_expected.push_back(method);
      }
    } else {
      if (!e.is_string()) ep.fail("expected \"refused\" or an object {\"METHOD\": \"refused\"}");
      expect_value(e, ep);
      c.refusals_expected = c.methods;
    }
  }
  if (j.contains("tags")) {
    schema_require_object(j["tags"], p.at("tags"));
    c.tags = j["tags"];
  }
  return c;
}

/// Line number (1-based) of byte offset `pos` in `text`.
int64_t text_line_of(const std::string& text, size_t pos) {
  pos = std::min(pos, text.size());
  return 1 + std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(pos), '\n');
}

}  // namespace

RunPlan run_plan_parse(const json& root, const std::string& file, const std::string& base_dir) {
  const SchemaPath p{file, ""};
  schema_require_object(root, p);
  schema_allow_keys(root, p, {"cases", "output", "description"});
  RunPlan plan;
  plan.source = file;
  if (!root.contains("cases")) p.fail("missing \"cases\"");
  const json& cases = root["cases"];
  if (!cases.is_array() || cases.empty()) p.at("cases").fail("expected a non-empty array");
  std::set<std::string> names;
  for (size_t i = 0; i < cases.size(); ++i) {
    RunCase c = parse_case(cases[i], p.at("cases").at(i), base_dir, static_cast<int>(i));
    if (!names.insert(c.name).second)
      p.at("cases").at(i).at("name").fail("case name '" + c.name + "' used twice");
    plan.cases.push_back(std::move(c));
  }
  if (root.contains("output")) {
    fs::path out(schema_string(root["output"], p.at("output")));
    if (out.is_relative()) out = fs::path(base_dir) / out;
    plan.output = out.lexically_normal().string();
  } else {
    fs::path out = fs::path(base_dir) / fs::path(file).stem();
    plan.output = out.string() + ".jsonl";
  }
  return plan;
}

RunPlan run_plan_read(const std::string& path) {
  const std::string text = run_file_read(path);
  json root;
  try {
    root = json::parse(text);
  } catch (const json::parse_error& e) {
    throw InputError(error_at(path, text_line_of(text, e.byte > 0 ? e.byte - 1 : 0),
                              std::string("invalid JSON: ") + e.what()));
  }
  std::string base = fs::path(path).parent_path().string();
  if (base.empty()) base = ".";
  return run_plan_parse(root, path, base);
}

}  // namespace hexrefine
