"""What every study under experiments/studies/ shares: its command line's common flags, the
provenance it stamps on what it writes, atomic writing of its JSON, JSON Lines and Markdown, and
the reading of a pipeline report's two checks under either report schema version.

A study is run as `python3 experiments/studies/NAME/run.py [--help]` from anywhere; its run.py
puts this folder on sys.path (two lines) and imports this module. Kept in one place so that a
study's records say where they come from in one shape, and a killed run never leaves half a
file behind (docs/experiments.md, "Studies").
"""

import argparse
import datetime
import json
import os
import pathlib
import subprocess
import sys

STUDIES = pathlib.Path(__file__).resolve().parent
REPO = STUDIES.parent.parent
RESULTS = REPO / "results"
BUILD = REPO / "build" / "experiments"
DEFAULT_HEXREFINE = BUILD / "hexrefine"
PYTHON_MODULE = BUILD / "python"
SHARED = REPO.parent / "shared"


# --- arguments -------------------------------------------------------------------------------


def study_arguments(description, out=RESULTS, hexrefine=False, report_only=False):
    """An argparse parser with the flags the studies share.

    @param description  the first line of the study's docstring (shown by --help)
    @param out          default of --out, the folder the study writes into; None: no --out
    @param hexrefine    add --hexrefine (the command-line binary; default build/experiments/
                        hexrefine of this source tree)
    @param report_only  add --report-only (rewrite the Markdown from the study's JSON, no runs)
    """
    parser = argparse.ArgumentParser(description=description)
    if out is not None:
        parser.add_argument("--out", default=str(out),
                            help="folder the study writes into (default %(default)s)")
    if hexrefine:
        parser.add_argument("--hexrefine", default=str(DEFAULT_HEXREFINE),
                            help="the hexrefine binary (default %(default)s)")
    if report_only:
        parser.add_argument("--report-only", action="store_true",
                            help="rewrite the report from the study's JSON without running")
    return parser


def run_command_study(description, command):
    """The run.py of a study the command runs itself (`hexrefine reproduce`, `hexrefine study`):
    --hexrefine, every other argument passed on to `hexrefine COMMAND`; exits with its status."""
    parser = study_arguments(description, out=None, hexrefine=True)
    args, rest = parser.parse_known_args()
    sys.exit(subprocess.run([args.hexrefine, command] + rest).returncode)


def first_line(docstring):
    """The first line of a module docstring, for study_arguments' description."""
    return docstring.strip().split("\n")[0]


def fail(script, message, status=2):
    """Prints `script: error: message` on stderr and exits with `status` (2: bad input or
    usage, 1: the operation failed)."""
    print("%s: error: %s" % (script, message), file=sys.stderr)
    sys.exit(status)


def import_hexrefine():
    """The Python module: from PYTHONPATH or an installed copy if there is one, else from this
    source tree's build (build/experiments/python), so a study needs no PYTHONPATH."""
    try:
        import hexrefine
    except ImportError:
        sys.path.insert(0, str(PYTHON_MODULE))
        try:
            import hexrefine
        except ImportError as error:
            fail(pathlib.Path(sys.argv[0]).name,
                 "cannot import the Python module hexrefine (%s); build it (target _hexrefine) "
                 "or set PYTHONPATH to its folder" % error)
    return hexrefine


# --- provenance ------------------------------------------------------------------------------


def git_commit(repo=REPO):
    """(HEAD's full commit id, whether the work tree differs from it); ("unknown", False)
    outside a git work tree."""
    try:
        head = subprocess.run(["git", "-C", str(repo), "rev-parse", "HEAD"], check=True,
                              capture_output=True, text=True).stdout.strip()
        dirty = subprocess.run(["git", "-C", str(repo), "diff", "--quiet", "HEAD"],
                               capture_output=True).returncode != 0
    except (OSError, subprocess.CalledProcessError):
        head, dirty = "unknown", False
    return head, dirty


PROVENANCE_KEYS = ("commit", "commit_dirty", "date", "timestamp", "hexrefine", "command_line",
                   "schema_version")


def provenance(hexrefine=None, schema_version=None, argv=None, now=None):
    """Where a study's records come from, one shape for every study:

        commit          the source tree's HEAD (40 hex digits, "unknown" outside git)
        commit_dirty    the work tree differed from HEAD
        date            UTC, ISO 8601 to the second with offset ("2026-11-27T10:00:00+00:00")
        timestamp       the same instant as the runner's records spell it ("...T10:00:00Z")
        hexrefine       the binary the study ran (a path), None where it ran none
        command_line    the study's own command line (sys.argv)
        schema_version  the pipeline report schema version of the reports the study read (an
                        integer; a sorted list where they differ; None where it read none)

    @param hexrefine       path of the binary run, or None
    @param schema_version  an int, an iterable of ints (the versions seen), or None
    @param argv            the command line (default sys.argv)
    @param now             a timezone-aware datetime (default: now, UTC)
    """
    commit, dirty = git_commit()
    now = now or datetime.datetime.now(datetime.timezone.utc)
    return {"commit": commit, "commit_dirty": dirty,
            "date": now.isoformat(timespec="seconds"),
            "timestamp": now.strftime("%Y-%m-%dT%H:%M:%SZ"),
            "hexrefine": str(hexrefine) if hexrefine is not None else None,
            "command_line": list(sys.argv if argv is None else argv),
            "schema_version": schema_versions(schema_version)}


def schema_versions(versions):
    """The provenance's schema_version of the versions a study read: None for none, the integer
    where they agree, their sorted list where they differ.

    @param versions  None, an int, or an iterable of ints"""
    if versions is None or isinstance(versions, int):
        return versions
    versions = sorted(set(versions))
    return versions[0] if len(versions) == 1 else (versions or None)


# --- atomic writing --------------------------------------------------------------------------


def write_text_atomic(path, text):
    """Writes `text` (UTF-8) to a temporary file in `path`'s folder (named after the process id,
    so two runs do not share it), then renames it onto `path`: a reader sees the old file or
    the new one, never a part. Creates the folder if it is missing."""
    path = pathlib.Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(".%s.%d.tmp" % (path.name, os.getpid()))
    try:
        tmp.write_text(text, encoding="utf-8")
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    return path


def write_json_atomic(path, value, indent=1, final_newline=True):
    """`value` as JSON (json.dumps with `indent`), with a final newline unless told otherwise
    (some studies' committed JSON has none), written atomically."""
    return write_text_atomic(path, json.dumps(value, indent=indent) +
                             ("\n" if final_newline else ""))


def write_jsonl_atomic(path, records):
    """One JSON object per line, written atomically."""
    return write_text_atomic(path, "".join(json.dumps(r) + "\n" for r in records))


def savefig_atomic(fig, path, dpi):
    """Saves a matplotlib figure as PNG through a temporary file in the same folder, closes it."""
    import matplotlib.pyplot as plt

    path = str(path)
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    tmp = path + ".tmp.png"
    fig.savefig(tmp, dpi=dpi)
    plt.close(fig)
    os.replace(tmp, path)


# --- report keys -----------------------------------------------------------------------------


def report_schema_version(report):
    """A report's or record's schema_version; 1 for records written before versioning (their
    keys are those of version 1, docs/report.md)."""
    return report.get("schema_version", 1)


def report_output_check(report):
    """The checker's report of the mesh that was written (the smoothed one when smoothing ran).

    Version 1: report["check"] is the refined mesh's, report["smoothing"]["check"] the smoothed
    output's. Version 2: report["check"] is the output's."""
    if report_schema_version(report) >= 2:
        return report["check"]
    smoothing = report.get("smoothing")
    return smoothing["check"] if smoothing else report["check"]


def report_refined_check(report):
    """The checker's report of the refined mesh before smoothing (the output when smoothing did
    not run).

    Version 1: report["check"]. Version 2: report["smoothing"]["refined_check"] when smoothing
    ran, else report["check"]."""
    if report_schema_version(report) >= 2:
        smoothing = report.get("smoothing")
        return smoothing["refined_check"] if smoothing else report["check"]
    return report["check"]
