/// \file
/// The compiled part of the Python module `hexrefine` (pybind11): the same library as the command
/// line, no second implementation. Meshes cross as numpy arrays (float64 n x 3 points, int32
/// m x 8 hexes in VTK order, int32 per-hex attributes); refinement runs the one pipeline
/// (algorithms/pipeline/pipeline.hpp) and returns its report as a dict with the CLI's keys. Long calls
/// release the GIL. Errors: bad input -> ValueError (naming the hex, node or spec), a refinement
/// that cannot be carried out -> hexrefine.RefinementError (a RuntimeError). The package around
/// it (hexrefine/__init__.py) adds the meshio bridge.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "algorithms/pipeline/pipeline.hpp"
#include "experiments/runner/runner.hpp"
#include "mesh/conformity.hpp"
#include "mesh/error.hpp"
#include "mesh/generators.hpp"
#include "mesh/io.hpp"
#include "mesh/quality.hpp"
#include "mesh/selection.hpp"

namespace py = pybind11;
using namespace py::literals;

namespace hexrefine {

namespace {

/// A JSON value as the Python value it reads as (through the json module: exact and simple).
py::object json_to_python(const nlohmann::json& j) {
  return py::module_::import("json").attr("loads")(j.dump());
}

nlohmann::json python_to_json(const py::object& o) {
  return nlohmann::json::parse(py::module_::import("json").attr("dumps")(o).cast<std::string>());
}

HexMesh mesh_from_arrays(const py::array& points_in, const py::array& hexes_in,
                         const py::dict& attributes) {
  const auto points =
      py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(points_in);
  if (!points || points.ndim() != 2 || points.shape(1) != 3)
    throw InputError("points: expected a float array of shape (n, 3)");
  if (!py::isinstance<py::array>(hexes_in) ||
      !(py::dtype::of<int64_t>().kind() == hexes_in.dtype().kind() ||
        hexes_in.dtype().kind() == 'u'))
    throw InputError("hexes: expected an integer array of shape (m, 8)");
  const auto hexes =
      py::array_t<int64_t, py::array::c_style | py::array::forcecast>::ensure(hexes_in);
  if (!hexes || hexes.ndim() != 2 || hexes.shape(1) != 8)
    throw InputError("hexes: expected an integer array of shape (m, 8)");
  HexMesh m;
  const int64_t n = points.shape(0), count = hexes.shape(0);
  if (n > INT32_MAX || count > INT32_MAX) throw InputError("more than 2^31 - 1 points or hexes");
  const auto p = points.unchecked<2>();
  m.points.resize(n);
  for (int64_t i = 0; i < n; ++i) {
    m.points[i] = Eigen::Vector3d(p(i, 0), p(i, 1), p(i, 2));
    if (!m.points[i].allFinite())
      throw InputError("point " + std::to_string(i) + " has a NaN or infinite coordinate");
  }
  const auto h = hexes.unchecked<2>();
  m.hexes.resize(count);
  for (int64_t e = 0; e < count; ++e)
    for (int k = 0; k < 8; ++k) {
      const int64_t v = h(e, k);
      if (v < 0 || v >= n)
        throw InputError("hex " + std::to_string(e) + ", node " + std::to_string(k) + ": id " +
                         std::to_string(v) + " out of range 0.." + std::to_string(n - 1));
      m.hexes[e][k] = static_cast<int32_t>(v);
    }
  for (const auto& [key, value] : attributes) {
    const std::string name = py::str(key);
    const auto a = py::array_t<int64_t, py::array::c_style | py::array::forcecast>::ensure(
        py::reinterpret_borrow<py::object>(value));
    if (!a || a.ndim() != 1 || a.shape(0) != count)
      throw InputError("attribute '" + name + "': expected an integer array of " +
                       std::to_string(count) + " values (one per hex)");
    HexAttribute attr{name, std::vector<int32_t>(count)};
    const auto r = a.unchecked<1>();
    for (int64_t e = 0; e < count; ++e) {
      if (r(e) < INT32_MIN || r(e) > INT32_MAX)
        throw InputError("attribute '" + name + "', hex " + std::to_string(e) +
                         ": value out of the int32 range");
      attr.values[e] = static_cast<int32_t>(r(e));
    }
    m.attributes.push_back(std::move(attr));
  }
  mesh_validate_ids(m, "HexMesh");
  return m;
}

py::array_t<double> points_array(const HexMesh& m) {
  py::array_t<double> out({static_cast<py::ssize_t>(m.points.size()), py::ssize_t{3}});
  auto w = out.mutable_unchecked<2>();
  for (size_t i = 0; i < m.points.size(); ++i)
    for (int k = 0; k < 3; ++k) w(i, k) = m.points[i][k];
  return out;
}

py::array_t<int32_t> hexes_array(const HexMesh& m) {
  py::array_t<int32_t> out({static_cast<py::ssize_t>(m.hexes.size()), py::ssize_t{8}});
  auto w = out.mutable_unchecked<2>();
  for (size_t e = 0; e < m.hexes.size(); ++e)
    for (int k = 0; k < 8; ++k) w(e, k) = m.hexes[e][k];
  return out;
}

py::dict attributes_dict(const HexMesh& m) {
  py::dict out;
  for (const HexAttribute& a : m.attributes)
    out[py::str(a.name)] =
        py::array_t<int32_t>(static_cast<py::ssize_t>(a.values.size()), a.values.data());
  return out;
}

std::vector<std::string> specs_of(const py::object& spec) {
  if (py::isinstance<py::str>(spec)) return {spec.cast<std::string>()};
  return spec.cast<std::vector<std::string>>();
}

}  // namespace

}  // namespace hexrefine

PYBIND11_MODULE(_hexrefine, m) {
  using namespace hexrefine;
  m.doc() = "Conformal refinement of all-hex meshes (the hexrefine C++ library).";
  static py::exception<OperationError> refinement_error(m, "RefinementError", PyExc_RuntimeError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InputError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const OperationError& e) {
      refinement_error(e.what());
    }
  });

  py::class_<HexMesh>(m, "HexMesh",
                      "An all-hex mesh: points (float64, n x 3), hexes (int32, m x 8, VTK/Exodus "
                      "vertex order: 0-3 one face counter-clockwise seen from inside... 4 above "
                      "0), and per-hex int32 attributes.")
      .def(py::init(&mesh_from_arrays), "points"_a, "hexes"_a, "attributes"_a = py::dict(),
           "From numpy arrays: points (n, 3) floats, hexes (m, 8) integer node ids in [0, n), "
           "attributes {name: (m,) integers}. ValueError naming the hex and node for a bad id, a "
           "repeated node in a hex, a NaN coordinate or a wrong shape.")
      .def_property_readonly("points", &points_array, "float64 array (n, 3), a copy")
      .def_property_readonly("hexes", &hexes_array, "int32 array (m, 8), a copy")
      .def_property_readonly("attributes", &attributes_dict,
                             "{name: int32 array (m,)}: block_id, template_tag, "
                             "refinement_level, parent_hex, ...; copies")
      .def_property_readonly("point_count", &HexMesh::point_count)
      .def_property_readonly("hex_count", &HexMesh::hex_count)
      .def("__repr__", [](const HexMesh& mesh) {
        return "<hexrefine.HexMesh: " + std::to_string(mesh.hex_count()) + " hexes, " +
               std::to_string(mesh.point_count()) + " points>";
      });

  m.def(
      "read",
      [](const std::string& path) {
        py::gil_scoped_release release;
        return mesh_read(path);
      },
      "path"_a,
      "Reads a mesh; the format follows from the extension (.mesh .vtk .vtu .msh .e/.exo .inp). "
      "ValueError naming the file and line on bad input.");
  m.def(
      "write",
      [](const HexMesh& mesh, const std::string& path, bool binary, bool ascii, bool compress,
         const py::dict& cell_data) {
        MeshWriteOptions o;
        o.binary = binary;
        o.ascii = ascii;
        o.compress = compress;
        for (const auto& [key, value] : cell_data)
          o.cell_scalars.push_back({py::str(key), value.cast<std::vector<double>>()});
        for (const auto& [name, values] : o.cell_scalars)
          if (values.size() != mesh.hexes.size())
            throw InputError("cell_data '" + name + "': expected one value per hex");
        py::gil_scoped_release release;
        mesh_write(path, mesh, o);
      },
      "mesh"_a, "path"_a, "binary"_a = false, "ascii"_a = false, "compress"_a = false,
      "cell_data"_a = py::dict(),
      "Writes a mesh atomically (format by extension); attributes travel where the format holds "
      "them, cell_data {name: m floats} as cell fields (VTK, VTU, Gmsh, Exodus). binary: VTK "
      "legacy BINARY, Gmsh 4.1 binary; VTU is appended binary data unless ascii, zlib-compressed "
      "with compress.");
  m.def(
      "generate",
      [](const std::string& name, const py::kwargs& params) {
        const Generator& g = generator_find(name);
        const nlohmann::json p = generator_params(g, python_to_json(params), name);
        py::gil_scoped_release release;
        return g.generate(p);
      },
      "name"_a,
      "Builds a generated mesh (brick, gear, cylinder, twisted-ring, stepped) from keyword "
      "parameters, as `hexrefine generate NAME --PARAM ...` does: e.g. generate('brick', "
      "dims=[10, 10, 10], size=[1, 1, 1]). Missing parameters take their defaults; a wrong name "
      "or kind raises ValueError.");
  m.def(
      "methods",
      [] {
        std::vector<std::string> names;
        for (const RefineMethod& method : refine_methods()) names.emplace_back(method.name);
        return names;
      },
      "The refinement methods by name.");
  m.def(
      "select",
      [](const HexMesh& mesh, const py::object& spec) {
        const std::vector<std::string> specs = specs_of(spec);
        Selection s;
        {
          py::gil_scoped_release release;
          s = select_hexes(mesh, specs);
        }
        return py::array_t<int32_t>(static_cast<py::ssize_t>(s.hexes.size()), s.hexes.data());
      },
      "mesh"_a, "spec"_a,
      "Hex ids (int32, ascending) selected by a spec of the CLI's selection language or a list "
      "of them, united: all, hexes:FILE, box:x0,y0,z0,x1,y1,z1, sphere:cx,cy,cz,r, "
      "boundary:nx,ny,nz[,deg], block:ID[,ID], random:FRACTION,SEED, blob:COUNT,SEED, "
      "surface:RANK[,DEG].");
  m.def(
      "refine",
      [](const HexMesh& mesh, const py::object& targets, const std::string& method, int passes,
         const std::string& buffer, bool smooth, bool ranking, const std::string& directional_order,
         bool propagation, bool ebe_only, const std::string& placement, int threads,
         bool allow_inverted, int64_t max_hexes, double max_edge_ratio,
         std::optional<int> smooth_sweeps, std::optional<int> smooth_joint_iterations,
         std::optional<int> smooth_joint_rounds, bool smooth_both_starts) {
        PipelineOptions o;
        o.method = method;
        if (py::isinstance<py::str>(targets) || py::isinstance<py::list>(targets) ||
            py::isinstance<py::tuple>(targets)) {
          bool strings = py::isinstance<py::str>(targets);
          if (!strings && py::len(targets) > 0)
            strings = py::isinstance<py::str>(targets.attr("__getitem__")(0));
          if (strings)
            o.select = specs_of(targets);
          else
            o.targets = targets.cast<std::vector<int32_t>>();
        } else {
          const auto ids =
              py::array_t<int64_t, py::array::c_style | py::array::forcecast>::ensure(targets);
          if (!ids || ids.ndim() != 1)
            throw InputError(
                "targets: expected hex ids (a 1-D integer array or list) or "
                "selection specs");
          std::vector<int32_t> t;
          const auto r = ids.unchecked<1>();
          for (py::ssize_t i = 0; i < r.shape(0); ++i) {
            if (r(i) < 0 || r(i) >= mesh.hex_count())
              throw InputError("targets: hex id " + std::to_string(r(i)) + " out of range 0.." +
                               std::to_string(mesh.hex_count() - 1));
            t.push_back(static_cast<int32_t>(r(i)));
          }
          o.targets = std::move(t);
        }
        if (o.targets) {
          std::sort(o.targets->begin(), o.targets->end());
          o.targets->erase(std::unique(o.targets->begin(), o.targets->end()), o.targets->end());
        }
        o.refine.passes = passes;
        o.refine.buffer = pass_buffer_from_name(buffer);
        o.refine.ranking = ranking;
        if (directional_order != "by_rank" && directional_order != "by_hex")
          throw InputError("directional_order: expected 'by_rank' or 'by_hex', got '" +
                           directional_order + "'");
        o.refine.directional_order =
            directional_order == "by_hex" ? DirectionalOrder::by_hex : DirectionalOrder::by_rank;
        o.refine.propagation = propagation;
        o.refine.ebe_only = ebe_only;
        o.refine.threads = threads;
        o.refine.allow_inverted = allow_inverted;
        if (placement.empty())
          o.refine.placement.method = pipeline_default_placement(smooth);
        else if (placement == "trilinear")
          o.refine.placement.method = PlacementMethod::trilinear;
        else if (placement == "untangle")
          o.refine.placement.method = PlacementMethod::untangle;
        else if (placement == "reference")
          o.refine.placement.method = PlacementMethod::reference;
        else if (placement != "optimized")
          throw InputError(
              "placement must be 'trilinear', 'reference', 'optimized' or 'untangle', got '" +
              placement + "'");
        o.smooth = smooth;
        if (!(max_edge_ratio == 0 || (max_edge_ratio >= 1 && max_edge_ratio <= 1e6)))
          throw InputError("max_edge_ratio must be 0 or in 1..1e6, got " +
                           std::to_string(max_edge_ratio));
        o.refine.placement.max_edge_ratio = max_edge_ratio;
        o.smoothing.max_edge_ratio = max_edge_ratio;
        // As the CLI: a budget without smoothing is refused, not ignored.
        if ((smooth_sweeps || smooth_joint_iterations || smooth_joint_rounds) && !smooth)
          throw InputError(std::string(smooth_sweeps             ? "smooth_sweeps"
                                       : smooth_joint_iterations ? "smooth_joint_iterations"
                                                                 : "smooth_joint_rounds") +
                           " needs smooth=True");
        if (smooth_sweeps && (*smooth_sweeps < 1 || *smooth_sweeps > 1000000))
          throw InputError("smooth_sweeps must be in 1..1000000, got " +
                           std::to_string(*smooth_sweeps));
        if (smooth_joint_iterations &&
            (*smooth_joint_iterations < 0 || *smooth_joint_iterations > 1000000))
          throw InputError("smooth_joint_iterations must be in 0..1000000, got " +
                           std::to_string(*smooth_joint_iterations));
        if (smooth_joint_rounds && (*smooth_joint_rounds < 1 || *smooth_joint_rounds > 1000))
          throw InputError("smooth_joint_rounds must be in 1..1000, got " +
                           std::to_string(*smooth_joint_rounds));
        if (smooth_sweeps) o.smoothing.max_sweeps = *smooth_sweeps;
        if (smooth_joint_rounds) o.smoothing.joint_rounds = *smooth_joint_rounds;
        if (smooth_joint_iterations) o.smoothing.joint_iterations = *smooth_joint_iterations;
        // As the CLI's --smooth-both-starts.
        if (smooth_both_starts && !smooth) throw InputError("smooth_both_starts needs smooth=True");
        if (smooth_both_starts && o.refine.placement.method != PlacementMethod::untangle)
          throw InputError(
              "smooth_both_starts smooths from untangle and from optimized: it takes no "
              "placement but 'untangle'");
        o.smoothing_both_starts = smooth_both_starts;
        o.max_hexes = max_hexes;
        PipelineResult r;
        {
          py::gil_scoped_release release;
          r = pipeline_run(mesh, o);
        }
        return py::make_tuple(std::move(r.mesh), json_to_python(pipeline_report(r, o)));
      },
      "mesh"_a, "targets"_a, "method"_a = "selective", "passes"_a = 1, "buffer"_a = "layer",
      "smooth"_a = false, "ranking"_a = true, "directional_order"_a = "by_hex",
      "propagation"_a = true, "ebe_only"_a = false, "placement"_a = "", "threads"_a = 1,
      "allow_inverted"_a = false, "max_hexes"_a = int64_t{2147483647}, "max_edge_ratio"_a = 20.0,
      "smooth_sweeps"_a = py::none(), "smooth_joint_iterations"_a = py::none(),
      "smooth_joint_rounds"_a = py::none(), "smooth_both_starts"_a = false,
      "Refines `targets` (hex ids, or selection specs) by `method` through the pipeline: plan, "
      "apply, place the new nodes (placement 'optimized', the thesis' 'trilinear', 'reference': "
      "the templates' reference positions, or 'untangle': trilinear with inverted children "
      "untangled, the better start for smooth=True; none given: 'untangle' with smooth=True, else "
      "'optimized'), check "
      "against the input, optionally smooth and check again. Returns (mesh, report): the mesh "
      "with template_tag, refinement_level and parent_hex attributes, the report a dict with the "
      "keys of `hexrefine refine --report`. `buffer` (passes > 1): 'layer' (the thesis' rule), "
      "'transitions' or 'none'. `threads`: for the template application, node placement, "
      "smoothing and the check (the same mesh for any count). `max_edge_ratio`: optimized "
      "placement and smoothing give no hex an edge ratio above it or its ratio before (0: no "
      "cap). `smooth_sweeps`, `smooth_joint_iterations`, `smooth_joint_rounds` (smooth=True "
      "only; None: 20, 1000 and 3): the smoothing's budget (refine --smooth-sweeps, "
      "--smooth-joint-iterations, --smooth-joint-rounds). `smooth_both_starts` (smooth=True, "
      "no placement but 'untangle'): smooth from untangle and from optimized, keep the higher "
      "minimum (refine --smooth-both-starts). "
      "RefinementError if the method "
      "refuses or the result "
      "is invalid (unless an ablation switch or allow_inverted); ValueError for bad input.");
  m.def(
      "check",
      [](const HexMesh& mesh, const HexMesh* reference) {
        MeshCheckReport r;
        {
          py::gil_scoped_release release;
          r = mesh_check(mesh, reference);
        }
        return json_to_python(nlohmann::json(r));
      },
      "mesh"_a, "reference"_a = nullptr,
      "The checker's report as a dict (conformal, valid, non_conformal_faces, hanging_nodes, "
      "inverted_hexes, doublets, min/mean scaled Jacobian, histogram, ...), against `reference` "
      "(the mesh before refinement) if given.");
  m.def(
      "quality",
      [](const HexMesh& mesh, const std::string& metric) {
        double (*f)(const HexCorners&) = nullptr;
        if (metric == "scaled_jacobian")
          f = hex_scaled_jacobian;
        else if (metric == "shape")
          f = hex_shape;
        else if (metric == "condition")
          f = hex_condition;
        else if (metric == "edge_ratio")
          f = hex_edge_ratio;
        else if (metric == "jacobian")
          f = hex_jacobian;
        else if (metric == "volume")
          f = hex_volume;
        else
          throw InputError(
              "metric must be scaled_jacobian, shape, condition, edge_ratio, "
              "jacobian or volume, got '" +
              metric + "'");
        py::array_t<double> out(mesh.hex_count());
        auto w = out.mutable_unchecked<1>();
        py::gil_scoped_release release;
        for (int32_t h = 0; h < mesh.hex_count(); ++h) w(h) = f(hex_points(mesh, h));
        return out;
      },
      "mesh"_a, "metric"_a = "scaled_jacobian",
      "One Verdict-compatible metric per hex (float64 array of m): scaled_jacobian (unit cube "
      "1), shape, condition, edge_ratio, jacobian, volume.");
  m.def(
      "run",
      [](const py::object& cases, const std::string& output, const std::string& base_dir) {
        RunPlan plan;
        if (py::isinstance<py::str>(cases))
          plan = run_plan_read(cases.cast<std::string>());
        else
          plan = run_plan_parse(python_to_json(cases), "cases", base_dir);
        RunSettings settings;
        settings.output = output;
        settings.environment = run_environment_detect();
        {
          py::gil_scoped_release release;
          run_plan_execute(plan, settings, case_execute);
        }
        py::list records;
        for (const nlohmann::json& r : jsonl_read(output).records)
          records.append(json_to_python(r));
        return records;
      },
      "cases"_a, "output"_a, "base_dir"_a = ".",
      "Runs a case list (a dict in the case-file schema, or a case file's path) as `hexrefine "
      "run` does, appending records to `output` (JSONL), and returns the records.");
}
