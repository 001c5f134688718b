/// \file
/// case_execute: the runner's real executor. Builds (generate) or reads (file) the case's mesh
/// once, then runs each method through the refinement pipeline (algorithms/pipeline/pipeline.hpp) on the
/// same selection; the record is the pipeline's report plus what only the runner knows (the
/// input's description, wall and CPU time, the saved mesh).

#include <chrono>
#include <filesystem>

#include "algorithms/pipeline/pipeline.hpp"
#include "experiments/runner/runner.hpp"
#include "mesh/error.hpp"
#include "mesh/generators.hpp"
#include "mesh/io.hpp"
#include "mesh/quality.hpp"

namespace hexrefine {

namespace {

using nlohmann::json;

/// The case's input mesh; `input` receives the record's "input" object.
HexMesh case_mesh(const RunCase& c, json& input) {
  if (c.mesh.contains("file")) {
    const std::string path = c.mesh["path"].get<std::string>();
    input = json{{"file", c.mesh["file"]}, {"sha256", sha256_file(path)}};
    return mesh_read(path);
  }
  input = c.mesh;
  json params = c.mesh;
  params.erase("generate");
  return generator_find(c.mesh["generate"].get<std::string>()).generate(params);
}

}  // namespace

void case_execute(const RunCase& c, const std::vector<std::string>& methods, const RunEmit& emit) {
  json input;
  const HexMesh mesh = case_mesh(c, input);
  input["hexes"] = mesh.hex_count();
  input["initial_min_scaled_jacobian"] = mesh_min_scaled_jacobian(mesh);

  for (const std::string& method : methods) {
    PipelineOptions o;
    o.method = method;
    o.select = c.select;
    o.refine = c.options;
    o.smooth = c.smooth;
    const auto start = std::chrono::steady_clock::now();
    PipelineResult r;
    try {
      r = pipeline_run(mesh, o);
    } catch (const OperationError& e) {
      emit(method, json{{"input", input}, {"error", e.what()}, {"error_kind", "operation"}});
      continue;
    } catch (const InputError& e) {
      // This method's answer to a bad input (an inverted hex, an invalid mesh, a bad spec).
      emit(method, json{{"input", input}, {"error", e.what()}, {"error_kind", "input"}});
      continue;
    }
    json fields = pipeline_report(r, o);
    fields.erase("options");  // the runner stamps the case's canonical options (record key)
    fields["selection"]["specs"] = c.select_given;
    fields["input"] = input;
    fields["wall_seconds"] =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    // The refine stage's CPU time (plan, apply, placement), beside its wall time_seconds.
    fields["cpu_seconds"] = r.stage_cpu_seconds["refine"];
    if (!c.save_mesh_dir.empty()) {
      const std::string name = run_mesh_file_name(c.name, method);
      MeshWriteOptions write_options;
      write_options.cell_scalars.emplace_back("scaled_jacobian", mesh_scaled_jacobians(r.mesh));
      mesh_write((std::filesystem::path(c.save_mesh_dir) / name).string(), r.mesh, write_options);
      fields["mesh_file"] = (std::filesystem::path(c.save_mesh_dir).filename() / name).string();
    }
    emit(method, std::move(fields));
  }
}

}  // namespace hexrefine
