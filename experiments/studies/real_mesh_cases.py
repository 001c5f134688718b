"""What the studies that rerun cases of the real-mesh study share (worst_hexes, smoothing_budget,
smoothing_starts through the binary; edge_ratio_cap and smooth_start through the Python module):
their common options, where a recorded mesh is found, the `hexrefine refine` command line of a
recorded smoothed case, and the study's optimized cases with their meshes."""

import json
import os
import pathlib

import harness

REPO = harness.REPO


def add_rerun_arguments(parser):
    """--records and --meshes (repeatable) on a study_arguments parser."""
    parser.add_argument("--records", default=str(REPO / "results" / "real_meshes.jsonl"),
                        help="the real-mesh study's records (default %(default)s)")
    parser.add_argument("--meshes", action="append", default=None,
                        help="a folder holding the study's meshes (repeatable; default "
                        "../shared/meshes)")


def rerun_arguments(description):
    """The parser of a study that reruns recorded cases with the binary: --out, --hexrefine,
    --report-only, --records, --meshes."""
    parser = harness.study_arguments(description, hexrefine=True, report_only=True)
    add_rerun_arguments(parser)
    return parser


def mesh_folders(args):
    """The --meshes folders, ../shared/meshes when none is given."""
    return args.meshes or [str(REPO.parent / "shared" / "meshes")]


def find_mesh(record, folders):
    """The path of a record's input mesh, found by file name in `folders`, or None."""
    name = os.path.basename(record["input"]["file"])
    for folder in folders:
        path = pathlib.Path(folder) / name
        if path.exists():
            return path
    return None


def smoothed_refine_argv(hexrefine, mesh, out, record):
    """`hexrefine refine MESH OUT ... --smooth --threads 1` with the record's method, targets,
    passes, buffer and edge-ratio cap."""
    argv = [str(hexrefine), "refine", str(mesh), str(out), "--method", record["method"]]
    for spec in record["selection"]["specs"]:
        argv += ["--select", spec]
    options = record["options"]
    argv += ["--passes", str(options["passes"])]
    if options["passes"] > 1:
        argv += ["--buffer", options["buffer"]]
    cap = options["placement"]["max_edge_ratio"]
    if cap != 20.0:
        argv += ["--max-edge-ratio", repr(cap)]
    return argv + ["--smooth", "--threads", "1"]


# --- the optimized cases, through the Python module (edge_ratio_cap, smooth_start) -------------


def optimized_cases(script, path, max_output_hexes):
    """The optimized (default-arm), refined cases of the real-mesh study (the records name their
    options)."""
    cases = []
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except OSError as error:
        harness.fail(script, "cannot read %s: %s" % (path, error))
    for number, line in enumerate(lines, 1):
        try:
            r = json.loads(line)
        except ValueError as error:
            harness.fail(script, "%s line %d: %s" % (path, number, error))
        tags = r.get("tags", {})
        # Records before issue 28 tag placement "optimized"; since, the unsmoothed default arm.
        if tags.get("study") != "real_meshes" or (tags.get("placement") != "optimized"
                                                  and tags.get("arm") != "default"):
            continue
        if r.get("error") or harness.report_refined_check(r)["hexes"] > max_output_hexes:
            continue
        if r["refined_parents"]["hexes"] == 0:
            continue
        mesh_file = REPO / "experiments" / r["input"]["file"] if not os.path.isabs(
            r["input"]["file"]) else pathlib.Path(r["input"]["file"])
        cases.append({"mesh": tags["mesh"], "kind": tags["kind"], "method": r["method"],
                      "file": str(mesh_file.resolve()), "specs": r["selection"]["specs"],
                      "passes": r["options"]["passes"], "buffer": r["options"]["buffer"]})
    return cases


def smoothed_case_figures(report, unsmoothed_edge_ratio=True):
    """What edge_ratio_cap and smooth_start record of a `refine --smooth` report, in their
    records' key order: the refined parents' minimum, the refined (unsmoothed) and the smoothed
    output's minimum scaled Jacobian, the largest edge ratio (the unsmoothed one only with
    `unsmoothed_edge_ratio`), both valid, the refine and smooth stages' seconds, and the report's
    schema version."""
    check = harness.report_refined_check(report)
    smoothed = harness.report_output_check(report)
    figures = {"parents_min": report["refined_parents"]["min_scaled_jacobian"],
               "min": check["min_scaled_jacobian"],
               "smoothed_min": smoothed["min_scaled_jacobian"]}
    if unsmoothed_edge_ratio:
        figures["edge_ratio"] = check["max_edge_ratio"]
    figures.update(smoothed_edge_ratio=smoothed["max_edge_ratio"],
                   valid=check["valid"] and smoothed["valid"],
                   refine_s=report["stage_seconds"]["refine"],
                   smooth_s=report["stage_seconds"].get("smooth", 0.0),
                   schema_version=harness.report_schema_version(report))
    return figures


def fmt(value, digits=3):
    """A number for these studies' tables: thousands separators for integers, `digits`
    significant digits otherwise, "–" for None."""
    if value is None:
        return "–"
    if isinstance(value, int):
        return "{:,}".format(value)
    return "%.*g" % (digits, value)


def optimized_cases_with_meshes(script, description):
    """The command line (--out, --records, --max-output-hexes), the study's optimized cases, and
    each case with its input mesh (read once per file): what edge_ratio_cap and smooth_start
    share."""
    parser = harness.study_arguments(description)
    parser.add_argument("--records", default=str(REPO / "results" / "real_meshes.jsonl"),
                        help="the real-mesh study's records (default %(default)s)")
    parser.add_argument("--max-output-hexes", type=int, default=60000,
                        help="the cases of at most this many output hexes (default %(default)s)")
    args = parser.parse_args()
    hexrefine = harness.import_hexrefine()
    cases = optimized_cases(script, pathlib.Path(args.records), args.max_output_hexes)
    if not cases:
        harness.fail(script, "%s: no optimized real-mesh cases to run" % args.records)
    meshes = {}
    pairs = []
    for case in cases:
        if case["file"] not in meshes:
            meshes[case["file"]] = hexrefine.read(case["file"])
        pairs.append((case, meshes[case["file"]]))
    return args, cases, pairs
