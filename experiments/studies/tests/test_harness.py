"""The studies' harness (experiments/studies/harness.py): the two report checks under both report
schema versions, the provenance's shape, atomic writing; and every study's --help."""

import json
import pathlib
import subprocess
import sys

import pytest

STUDIES = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(STUDIES))
import harness  # noqa: E402

REFINED = {"hexes": 27, "min_scaled_jacobian": 0.0439, "valid": True}
SMOOTHED = {"hexes": 27, "min_scaled_jacobian": 0.5458, "valid": True}
UNSMOOTHED = {"hexes": 27, "min_scaled_jacobian": 0.3077, "valid": True}


def v1_smoothed():
    """Version 1 after --smooth: the top-level check is the refined mesh's."""
    return {"schema_version": 1, "check": dict(REFINED),
            "smoothing": {"stats": {}, "check": dict(SMOOTHED)}}


def v2_smoothed():
    """Version 2 after --smooth: the top-level check is the output's, the refined mesh's is
    smoothing.refined_check."""
    return {"schema_version": 2, "check": dict(SMOOTHED),
            "smoothing": {"stats": {}, "refined_check": dict(REFINED)}}


def test_version_1_smoothed_output_is_the_smoothing_check_refined_the_top_level():
    report = v1_smoothed()
    assert harness.report_output_check(report)["min_scaled_jacobian"] == 0.5458
    assert harness.report_refined_check(report)["min_scaled_jacobian"] == 0.0439


def test_version_2_smoothed_output_is_the_top_level_refined_the_smoothing_refined_check():
    report = v2_smoothed()
    assert harness.report_output_check(report)["min_scaled_jacobian"] == 0.5458
    assert harness.report_refined_check(report)["min_scaled_jacobian"] == 0.0439


@pytest.mark.parametrize("version", [None, 1, 2])
def test_without_smoothing_both_checks_are_the_top_level_one(version):
    report = {"check": dict(UNSMOOTHED)}
    if version is not None:
        report["schema_version"] = version
    assert harness.report_output_check(report) is report["check"]
    assert harness.report_refined_check(report) is report["check"]


def test_a_record_before_versioning_reads_as_version_1():
    report = v1_smoothed()
    del report["schema_version"]
    assert harness.report_schema_version(report) == 1
    assert harness.report_output_check(report)["min_scaled_jacobian"] == 0.5458
    assert harness.report_refined_check(report)["min_scaled_jacobian"] == 0.0439


def test_version_1_smoothing_without_its_check_is_an_error_not_the_refined_check():
    report = v1_smoothed()
    del report["smoothing"]["check"]
    with pytest.raises(KeyError):
        harness.report_output_check(report)


def test_provenance_has_one_shape():
    stamp = harness.provenance("build/experiments/hexrefine", {2, 1, 2}, argv=["run.py", "-x"])
    assert tuple(stamp) == harness.PROVENANCE_KEYS
    assert len(stamp["commit"]) == 40 or stamp["commit"] == "unknown"
    assert isinstance(stamp["commit_dirty"], bool)
    assert stamp["date"].endswith("+00:00") and stamp["timestamp"].endswith("Z")
    assert stamp["date"][:19] == stamp["timestamp"][:19]
    assert stamp["hexrefine"] == "build/experiments/hexrefine"
    assert stamp["command_line"] == ["run.py", "-x"]
    assert stamp["schema_version"] == [1, 2]
    assert harness.provenance(schema_version={2})["schema_version"] == 2
    assert harness.provenance(schema_version=set())["schema_version"] is None
    assert harness.provenance()["hexrefine"] is None


def test_atomic_writes_leave_only_the_file(tmp_path):
    harness.write_json_atomic(tmp_path / "a.json", {"x": [1, 2]})
    harness.write_json_atomic(tmp_path / "b.json", [1], indent=2, final_newline=False)
    harness.write_jsonl_atomic(tmp_path / "c.jsonl", [{"a": 1}, {"b": 2}])
    harness.write_text_atomic(tmp_path / "a.json", harness.json.dumps({"y": 1}) + "\n")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.json", "b.json", "c.jsonl"]
    assert json.loads((tmp_path / "a.json").read_text()) == {"y": 1}
    assert (tmp_path / "b.json").read_text() == "[\n  1\n]"
    assert (tmp_path / "c.jsonl").read_text() == '{"a": 1}\n{"b": 2}\n'


def test_a_failed_write_keeps_the_old_file_and_no_temporary(tmp_path):
    harness.write_text_atomic(tmp_path / "a.md", "old\n")
    with pytest.raises(TypeError):
        harness.write_json_atomic(tmp_path / "a.md", {"not serialisable": object()})
    assert (tmp_path / "a.md").read_text() == "old\n"
    assert [p.name for p in tmp_path.iterdir()] == ["a.md"]


SCRIPTS = sorted(str(p.relative_to(STUDIES)) for p in STUDIES.glob("*/*.py")
                 if p.parent.name != "tests")


def test_every_study_folder_has_a_run_script():
    folders = {p.parent for p in STUDIES.glob("*/*.py") if p.parent.name != "tests"}
    assert len(folders) >= 19
    assert sorted(f.name for f in folders if not (f / "run.py").exists()) == []


@pytest.mark.parametrize("script", SCRIPTS)
def test_every_study_script_answers_help(script):
    done = subprocess.run([sys.executable, str(STUDIES / script), "--help"],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith("usage: ")
