"""The JSON Schemas of docs/schema/ against fresh output of every front end: `hexrefine refine
--report`, the records of `hexrefine run` and the Python module's refine report and run records.
Also: a report without its counts is rejected, the open objects take keys the schema does not
list, and docs/report.md names every key of both schemas. Run by ctest (test report_schema) with
HEXREFINE_EXE, HEXREFINE_SOURCE_DIR and PYTHONPATH on the build tree."""

import copy
import json
import os
import pathlib
import subprocess

import jsonschema
import pytest

SOURCE = pathlib.Path(os.environ.get("HEXREFINE_SOURCE_DIR", pathlib.Path(__file__).parents[2]))
EXE = os.environ.get("HEXREFINE_EXE", str(SOURCE / "build" / "experiments" / "hexrefine"))
SCHEMA_DIR = SOURCE / "docs" / "schema"
L_SHAPE = ["boundary:-1,0,0", "boundary:0,0,-1"]


def load(name):
    return json.loads((SCHEMA_DIR / name).read_text())


REPORT_SCHEMA = load("report.schema.json")
RECORD_SCHEMA = load("record.schema.json")


def validator(schema):
    """A draft 2020-12 validator that resolves the record schema's reference to the report
    schema locally: through `referencing` (jsonschema >= 4.18), else through RefResolver (Debian
    12's python3-jsonschema 4.10)."""
    try:
        from referencing import Registry, Resource
    except ImportError:
        store = {s["$id"]: s for s in (REPORT_SCHEMA, RECORD_SCHEMA)}
        resolver = jsonschema.RefResolver.from_schema(schema, store=store)
        return jsonschema.Draft202012Validator(schema, resolver=resolver)
    registry = Registry().with_resources(
        [(s["$id"], Resource.from_contents(s)) for s in (REPORT_SCHEMA, RECORD_SCHEMA)])
    return jsonschema.Draft202012Validator(schema, registry=registry)


REPORT = validator(REPORT_SCHEMA)
RECORD = validator(RECORD_SCHEMA)


def errors(validator, instance):
    return [e.message for e in validator.iter_errors(instance)]


def hexrefine_cli(*args, expect=0):
    r = subprocess.run([EXE, *map(str, args)], capture_output=True, text=True)
    assert r.returncode == expect, r.stdout + r.stderr
    return r.stdout


@pytest.fixture(scope="module")
def brick(tmp_path_factory):
    path = tmp_path_factory.mktemp("schema") / "brick.mesh"
    hexrefine_cli("generate", "brick", path, "--dims", "6,6,6")
    return path


def test_the_schemas_are_valid_draft_2020_12():
    for schema in (REPORT_SCHEMA, RECORD_SCHEMA):
        jsonschema.Draft202012Validator.check_schema(schema)
        assert schema["$schema"] == "https://json-schema.org/draft/2020-12/schema"


@pytest.mark.parametrize("method,extra", [("selective", ["--placement", "trilinear"]),
                                          ("sheet", ["--smooth"]),
                                          ("selective", ["--smooth", "--placement", "untangle"])])
def test_cli_refine_report_validates(brick, tmp_path, method, extra):
    report_path = tmp_path / "r.json"
    args = ["refine", brick, tmp_path / "out.vtu", "--method", method, "--report", report_path]
    for spec in L_SHAPE:
        args += ["--select", spec]
    hexrefine_cli(*args, *extra)
    report = json.loads(report_path.read_text())
    assert errors(REPORT, report) == []
    assert report["schema_version"] == 2
    assert report["input"] == str(brick) and report["output"] == str(tmp_path / "out.vtu")
    assert ("smoothing" in report) == ("--smooth" in extra)
    assert report["check"]["reference_compared"] and report["check"]["valid"]


def test_cli_run_records_validate(brick, tmp_path):
    cases = {"cases": [
        {"name": "L", "mesh": {"file": str(brick)}, "select": L_SHAPE, "smooth": True},
        {"name": "gen", "mesh": {"generate": "brick", "dims": [3, 3, 3]}, "select": ["all"],
         "methods": ["sheet"], "save_mesh": True, "options": {"placement": "trilinear"}},
        {"name": "bad-spec", "mesh": {"generate": "brick", "dims": [2, 2, 2]},
         "select": ["boxx:1"], "methods": ["selective"], "expect": "refused"}],
        "output": "r.jsonl"}
    (tmp_path / "c.json").write_text(json.dumps(cases))
    out = hexrefine_cli("run", tmp_path / "c.json", "--quiet", expect=2)  # the bad spec: exit 2
    assert out == ""
    records = [json.loads(line) for line in (tmp_path / "r.jsonl").read_text().splitlines()]
    assert [(r["case"], r["method"]) for r in records] == [
        ("L", "selective"), ("L", "sheet"), ("gen", "sheet"), ("bad-spec", "selective")]
    for r in records:
        assert errors(RECORD, r) == [], r
        assert r["schema_version"] == 2
    assert "smoothing" in records[0] and "mesh_file" in records[2]
    assert records[3]["error_kind"] == "input" and records[3]["expect"] == "refused"


def test_python_module_report_and_records_validate(tmp_path):
    hexrefine = pytest.importorskip("hexrefine")
    mesh = hexrefine.generate("brick", dims=[5, 5, 5])
    for smooth in (False, True):
        _, report = hexrefine.refine(mesh, L_SHAPE, method="selective", smooth=smooth)
        assert errors(REPORT, report) == []
        assert "input" not in report and ("smoothing" in report) == smooth
    records = hexrefine.run({"cases": [{"name": "b", "mesh": {"generate": "brick", "dims": [2, 2, 2]},
                                        "select": ["all"]}]}, str(tmp_path / "r.jsonl"))
    assert len(records) == 2
    for r in records:
        assert errors(RECORD, r) == []


@pytest.fixture(scope="module")
def report(brick, tmp_path_factory):
    tmp = tmp_path_factory.mktemp("report")
    hexrefine_cli("refine", brick, tmp / "o.mesh", "--method", "selective", "--select", "all",
                  "--smooth", "--report", tmp / "r.json")
    return json.loads((tmp / "r.json").read_text())


def test_the_check_is_the_written_meshs_the_refined_one_is_named_so(brick, tmp_path):
    """schema_version 2: the top-level check describes the mesh written (the smoothed one), the
    refined mesh's check before smoothing is smoothing.refined_check."""
    args = ["refine", brick, tmp_path / "o.mesh", "--method", "selective", "--smooth", "--report",
            tmp_path / "r.json"]
    for spec in L_SHAPE:
        args += ["--select", spec]
    hexrefine_cli(*args)
    report = json.loads((tmp_path / "r.json").read_text())
    hexrefine_cli("check", tmp_path / "o.mesh", "--reference", brick, "--report",
                  tmp_path / "c.json")
    written = json.loads((tmp_path / "c.json").read_text())
    for key in ("hexes", "nodes", "valid", "inverted_hexes"):
        assert report["check"][key] == written[key], key
    assert report["check"]["min_scaled_jacobian"] == pytest.approx(
        written["min_scaled_jacobian"], abs=1e-9)
    smoothing = report["smoothing"]
    assert "check" not in smoothing
    refined = smoothing["refined_check"]["min_scaled_jacobian"]
    assert refined == pytest.approx(smoothing["stats"]["min_scaled_jacobian_before"], abs=1e-9)
    assert written["min_scaled_jacobian"] > refined + 0.01  # the smoothing moved the minimum


@pytest.mark.parametrize("path", [("refine",), ("check",), ("schema_version",),
                                  ("refine", "final_hexes"), ("refine", "initial_hexes"),
                                  ("refine", "placement"), ("check", "inverted_hexes"),
                                  ("check", "conformal"), ("smoothing", "refined_check", "hexes"),
                                  ("selection", "hexes"), ("stage_seconds", "total")])
def test_a_report_without_its_counts_is_rejected(report, path):
    assert errors(REPORT, report) == []
    broken = copy.deepcopy(report)
    parent = broken
    for key in path[:-1]:
        parent = parent[key]
    del parent[path[-1]]
    assert errors(REPORT, broken) != [], path


def test_wrong_types_and_unknown_keys_outside_the_open_objects_are_rejected(report):
    for change in (lambda r: r["refine"].update(final_hexes="8060"),
                   lambda r: r["check"].update(conformal=1),
                   lambda r: r["check"]["scaled_jacobian_histogram"]["counts"].pop(),
                   lambda r: r["options"]["placement"].update(method="nearest"),
                   lambda r: r.update(schema_version=1),  # the keys of version 1
                   lambda r: r.update(final_hexes=8060),  # the flat keys of the old records
                   lambda r: r["selection"].update(count=3),
                   lambda r: r["options"].pop("threads")):
        broken = copy.deepcopy(report)
        change(broken)
        assert errors(REPORT, broken) != []


def test_the_open_objects_take_keys_other_branches_add(report):
    extended = copy.deepcopy(report)
    extended["refine"]["placement_fallback_untangled"] = 0
    extended["refine"]["placement"]["reference_nodes"] = 12
    extended["refine"]["a_new_count"] = 1
    extended["options"]["placement"]["method"] = "reference"
    extended["check"]["a_new_check"] = 0
    extended["smoothing"]["stats"].update(nodes_undone=0, warning="stopped early")
    assert errors(REPORT, extended) == []
    extended["refine"]["placement_fallback_untangled"] = -1  # listed keys keep their types
    assert errors(REPORT, extended) != []


def test_a_record_is_a_result_or_an_error():
    ident = {"case": "a", "case_index": 0, "method": "sheet", "method_index": 0,
             "options": {"ranking": True, "directional_order": "by_hex", "propagation": True,
                         "ebe_only": False, "passes": 1, "buffer": "layer",
                         "allow_inverted": False, "smooth": False,
                         "placement": {"method": "optimized", "active_ratio": 0.9,
                                       "max_sweeps": 8, "smooth_sweeps": 0, "layers": 0,
                                       "joint_iterations": 100, "max_edge_ratio": 20}},
             "tags": {}, "commit": "unknown", "commit_dirty": False,
             "machine": {"cpu": "x", "cores": 2}, "build_type": "release",
             "timestamp": "2026-11-26T12:00:00Z", "schema_version": 2}
    error = dict(ident, error="cannot refine", error_kind="operation")
    assert errors(RECORD, error) == []
    assert errors(RECORD, dict(error, error_kind="crash")) != []
    assert errors(RECORD, ident) != []  # neither the report's keys nor an error
    missing = dict(error)
    del missing["timestamp"]
    assert errors(RECORD, missing) != []


def schema_keys(node, out):
    if isinstance(node, dict):
        for key, value in node.get("properties", {}).items():
            out.add(key)
            schema_keys(value, out)
        for key, value in node.items():
            if key != "properties":
                schema_keys(value, out)
    elif isinstance(node, list):
        for value in node:
            schema_keys(value, out)
    return out


def test_docs_report_md_holds_the_schemas_key_tables_and_names_every_key():
    text = (SOURCE / "docs" / "report.md").read_text()
    keys = schema_keys(REPORT_SCHEMA, set()) | schema_keys(RECORD_SCHEMA, set())
    assert len(keys) > 100
    missing = sorted(k for k in keys if f"`{k}`" not in text)
    assert missing == []
    result = subprocess.run(["/usr/bin/python3",
                             str(SOURCE / "experiments" / "tools" / "key_tables.py")],
                            capture_output=True, text=True, check=True)
    assert result.stdout.strip() in text  # else: python3 experiments/tools/key_tables.py --update
    assert "## Changelog" in text and "schema_version 1" in text and "schema_version 2" in text
