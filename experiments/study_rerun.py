"""What the scripts that rerun cases of the real-mesh study share (worst_hexes_study.py,
smoothing_budget.py): their common options, where a recorded mesh is found, and the `hexrefine
refine` command line of a recorded smoothed case."""

import os
import pathlib

REPO = pathlib.Path(__file__).resolve().parent.parent


def add_rerun_arguments(parser):
    """--records, --meshes (repeatable), --out, --hexrefine, --report-only."""
    parser.add_argument("--records", default=str(REPO / "results" / "real_meshes.jsonl"))
    parser.add_argument("--meshes", action="append", default=None)
    parser.add_argument("--out", default=str(REPO / "results"))
    parser.add_argument("--hexrefine",
                        default=str(REPO / "build" / "experiments" / "hexrefine"))
    parser.add_argument("--report-only", action="store_true")


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
