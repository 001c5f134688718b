/// \file
/// The compiled part of the Python module `hexrefine` (pybind11): the same library as the command
/// line, no second implementation. Meshes cross as numpy arrays (float64 n x 3 points, int32
/// m x 8 hexes in VTK order, int32 per-hex attributes); refinement runs the one pipeline
/// (algorithms/pipeline/pipeline.hpp) and returns its report as a dict with the CLI's keys. Long
/// calls release the GIL. Errors: bad input -> ValueError (naming the hex, node or spec), a
/// refinement that cannot be carried out -> hexrefine.RefinementError (a RuntimeError). The package
/// around it (hexrefine/__init__.py) adds the meshio bridge.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "algorithms/pipeline/pipeline.hpp"
#include "algorithms/pipeline/pipeline_options_table.hpp"
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

/// A JSON scalar as Python writes it: True, 'untangle', 20.
std::string python_repr(const nlohmann::json& v) {
  if (v.is_boolean()) return v.get<bool>() ? "True" : "False";
  if (v.is_null()) return "None";
  if (v.is_string()) return "'" + v.get<std::string>() + "'";
  return v.dump();
}

/// The table's options as `hexrefine.refine`'s keywords: `smooth_sweeps`, `smooth=True`.
class PythonSpelling : public PipelineOptionSpelling {
 public:
  std::string setting(std::string_view key, const nlohmann::json& value) const override {
    return std::string(key) + "=" + python_repr(value);
  }
  std::string value(const nlohmann::json& value) const override { return python_repr(value); }
};

/// A keyword's value as a setting (pipeline_options_table.hpp): bool, int, float and str as
/// themselves, numpy scalars as the Python value they hold, None as not given (null); anything
/// else is a ValueError naming the keyword.
nlohmann::json python_setting(const std::string& key, py::handle value) {
  if (value.is_none()) return nullptr;
  if (py::isinstance<py::bool_>(value)) return value.cast<bool>();
  if (py::isinstance<py::str>(value)) return value.cast<std::string>();
  if (py::isinstance<py::int_>(value)) {
    const py::int_ i = py::reinterpret_borrow<py::int_>(value);
    if (i < py::int_(INT64_MIN) || i > py::int_(INT64_MAX))
      throw InputError(key + " must be in range, got " + std::string(py::str(value)));
    return i.cast<int64_t>();
  }
  if (py::isinstance<py::float_>(value)) return value.cast<double>();
  if (py::hasattr(value, "dtype") && py::hasattr(value, "item"))
    return python_setting(key, value.attr("item")());
  throw InputError(key + ": expected a bool, a number or a string, got a " +
                   std::string(py::str(value.get_type().attr("__name__"))));
}

/// The keywords as settings; an unknown one is a TypeError, as Python's own, with the one meant.
nlohmann::json python_settings(const py::kwargs& keywords) {
  nlohmann::json settings = nlohmann::json::object();
  for (const auto& [k, v] : keywords) {
    const std::string key = py::str(k);
    if (!pipeline_option_row(key)) {
      const std::string near = pipeline_option_key_closest(key);
      throw py::type_error("refine() got an unexpected keyword argument '" + key + "'" +
                           (near.empty() ? "" : " (did you mean " + near + "?)"));
    }
    settings[key] = python_setting(key, v);
  }
  return settings;
}

/// The table's rows as dicts (key, type, default, help in Python's spelling, values, range):
/// hexrefine/__init__.py builds refine's signature and docstring from them.
py::list python_option_rows() {
  const PythonSpelling spelling;
  static const char* const types[] = {"bool", "int", "float", "str"};
  py::list rows;
  for (const PipelineOptionRow& row : pipeline_option_rows()) {
    py::dict d;
    d["key"] = std::string(row.key);
    d["type"] = types[static_cast<int>(row.type)];
    d["default"] = json_to_python(row.default_value);
    d["help"] = pipeline_option_help_text(row, spelling);
    py::list values;
    for (std::string_view v : row.values) values.append(std::string(v));
    d["values"] = values;
    rows.append(d);
  }
  return rows;
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
      [](const HexMesh& mesh, const py::object& targets, const std::string& method, int threads,
         const py::kwargs& keywords) {
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
        pipeline_options_set(o, python_settings(keywords), PythonSpelling());
        o.refine.threads = threads;
        PipelineResult r;
        {
          py::gil_scoped_release release;
          r = pipeline_run(mesh, o);
        }
        return py::make_tuple(std::move(r.mesh), json_to_python(pipeline_report(r, o)));
      },
      "mesh"_a, "targets"_a, "method"_a = "selective", "threads"_a = 1,
      "Refines `targets` (hex ids, or selection specs) by `method` through the pipeline: plan, "
      "apply, place the new nodes, check against the input, optionally smooth and check again. "
      "Returns (mesh, report): the mesh with template_tag, refinement_level and parent_hex "
      "attributes, the report a dict with the keys of `hexrefine refine --report`. `threads`: "
      "for the template application, node placement, smoothing and the check (the same mesh for "
      "any count). The other keywords are the pipeline's options (hexrefine.refine's signature "
      "and docstring list them, from the one table of algorithms/pipeline/"
      "pipeline_options_table.hpp); None: the default. RefinementError if the method refuses or "
      "the result is invalid (unless an ablation switch or allow_inverted); ValueError for bad "
      "input.");
  m.def("refine_options", &python_option_rows,
        "The pipeline's options, one dict per option (key, type, default, help, values): the "
        "keywords of refine.");
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
