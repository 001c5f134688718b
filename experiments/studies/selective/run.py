#!/usr/bin/env python3
"""Two studies of the Selective Approach run through the Python module (the same library as the
command line), each writing its records as JSON and a Markdown report into results/:

- `cases`: the thesis' small configurations and their ablations (ranking system off, propagation
  scheme off, element-by-element only), on bricks whose hexes keep one local orientation and on
  the same brick with every hex's vertex order rotated at random (as in unstructured meshes,
  where the ranking system matters), plus the gear, the O-grid cylinder and the ellipsoid.
- `random`: 2,000 seeded target sets on jittered 4^3 and 6^3 bricks (uniform, checkerboard,
  isolated hexes, pairs touching along an edge only or at a vertex only, blobs), refined by both
  methods, the Selective Approach with the thesis' trilinear placement and with optimized
  placement; every output checked against its input.

    python3 experiments/studies/selective/run.py cases random [--out results] [--sets 2000]
"""

import os
import pathlib
import random as rnd
import sys
import time

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent.parent))
import harness  # noqa: E402

hexrefine = None  # the Python module, imported by main() (harness.import_hexrefine)
SHARED = pathlib.Path(os.environ.get("HEXREFINE_SHARED_DIR", harness.SHARED))

# The unit cube's corners in VTK order (mesh/hex_convention.hpp).
CORNERS = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0],
                    [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]])


def cube_rotations():
    """The 24 orientation-preserving symmetries of the cube as vertex permutations: a hex's
    vertices reordered by one of them describe the same positively oriented hex with other
    local axes."""
    out = []
    for perm in ([0, 1, 2], [0, 2, 1], [1, 0, 2], [1, 2, 0], [2, 0, 1], [2, 1, 0]):
        for signs in np.ndindex(2, 2, 2):
            r = np.zeros((3, 3))
            for row, col in enumerate(perm):
                r[row, col] = 1 if signs[row] == 0 else -1
            if np.linalg.det(r) < 0:
                continue
            moved = np.rint((CORNERS - 0.5) @ r.T + 0.5).astype(int)
            out.append([int(np.flatnonzero((CORNERS == m).all(axis=1))[0]) for m in moved])
    assert len(out) == 24
    return out


def rotate_hexes(mesh, seed):
    """The same mesh with each hex's vertex order rotated by a random cube symmetry."""
    rotations = cube_rotations()
    generator = np.random.default_rng(seed)
    hexes = mesh.hexes
    choice = generator.integers(0, 24, size=len(hexes))
    rotated = np.array([hexes[e][rotations[c]] for e, c in enumerate(choice)])
    return hexrefine.HexMesh(mesh.points, rotated, mesh.attributes)


def record_of(mesh, targets, method, **options):
    start = time.perf_counter()
    try:
        refined, report = hexrefine.refine(mesh, targets, method=method, **options)
    except hexrefine.RefinementError as error:
        return {"method": method, "options": options, "refused": str(error)}
    check = hexrefine.check(refined, mesh)
    stats = report["refine"]
    return {"method": method, "options": options, "targets": int(len(targets)),
            "hexes_in": mesh.hex_count, "hexes_out": refined.hex_count,
            "directional_hexes": stats["directional_hexes"],
            "directional_groups": stats["directional_groups"], "ranks": stats["ranks"],
            "doublets_resolved": stats["doublets_resolved"],
            "edges_split_by_propagation": stats["edges_split_by_propagation"],
            "conformal": check["conformal"], "valid": check["valid"],
            "non_conformal_faces": check["non_conformal_faces"],
            "hanging_nodes": check["hanging_nodes"], "inverted_hexes": check["inverted_hexes"],
            "doublets": check["doublets"], "min_scaled_jacobian": check["min_scaled_jacobian"],
            "seconds": time.perf_counter() - start}


# --- cases ---------------------------------------------------------------------------------------

def study_cases():
    l_shape = ["boundary:-1,0,0", "boundary:0,0,-1"]
    brick10 = hexrefine.generate("brick", dims=[10, 10, 10])
    rotated10 = rotate_hexes(brick10, seed=1)
    corner_ball = "sphere:1,0,1,0.5"
    ablations = [("", {}), (", --no-ranking", {"ranking": False}),
                 (", --no-propagation", {"propagation": False}), (", --ebe-only", {"ebe_only": True})]
    cases = []
    for suffix, options in ablations:
        cases.append(("L-shaped 10x10x10 (Table G-1)" + suffix, brick10, l_shape, options))
    for suffix, options in ablations:
        cases.append(("L-shaped, hexes in random local orientations" + suffix, rotated10, l_shape,
                      options))
    for n in (10, 20):
        cases.append((f"radial r=0.5 at corner, interval {n} (Table G-3)",
                      hexrefine.generate("brick", dims=[n, n, n]), corner_ball, {}))
    for suffix, options in ablations:
        cases.append(("radial interval 10, random local orientations" + suffix, rotated10,
                      corner_ball, options))
    cases.append(("4x4x4 left surface, 3 passes (Table H-2)",
                  hexrefine.generate("brick", dims=[4, 4, 4]), "boundary:-1,0,0", {"passes": 3}))
    cases.append(("gear teeth (block 2)", hexrefine.generate("gear"), "block:2", {}))
    cases.append(("O-grid cylinder, sphere r=0.5 at (0,0,0.5)", hexrefine.generate("cylinder"),
                  "sphere:0,0,0.5,0.5", {}))
    ellipsoid = SHARED / "meshes" / "ellipsoid.mesh"
    if ellipsoid.exists():
        m = hexrefine.read(str(ellipsoid))
        for r in (0.1, 0.25):
            cases.append((f"ellipsoid.mesh, sphere r={r} at (0 0 0)", m, f"sphere:0,0,0,{r}", {}))
    records = []
    for name, mesh, spec, options in cases:
        targets = hexrefine.select(mesh, spec)
        for placement in ("trilinear", "optimized"):
            r = record_of(mesh, targets, "selective", placement=placement, **options)
            r["case"] = name
            records.append(r)
    return records


def report_cases(records):
    lines = ["# Selective Approach: cases", "",
             "Written by `experiments/studies/selective/run.py cases` through the Python module; "
             "JSON: `selective_cases.json`. Every output checked against its input "
             "(`hexrefine.check(out, input)`). Ablation switches return their output: its "
             "defects are the experiment. \"Random local orientations\": the 10x10x10 brick with "
             "every hex's vertex order rotated by a random cube symmetry (seed 1), the same "
             "geometry, so the ranking system has to order directions that differ from hex to "
             "hex. Minimum scaled Jacobian with the thesis' trilinear node placement and with "
             "optimized placement (the default); the counts do not depend on placement.", "",
             "| case | targets | hexes in -> out | directional hexes / groups / ranks | edges split: "
             "doublets / propagation | conformal | non-conformal faces | hanging nodes | inverted "
             "| min SJ trilinear | min SJ optimized |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    by_case = {}
    for r in records:
        by_case.setdefault(r["case"], {})[r["options"]["placement"]] = r
    for name, pair in by_case.items():
        t, o = pair["trilinear"], pair["optimized"]
        if "refused" in t:
            lines.append(f"| {name} | refused: {t['refused']} |||||||||")
            continue
        lines.append(
            f"| {name} | {t['targets']} | {t['hexes_in']} -> {t['hexes_out']} | "
            f"{t['directional_hexes']} / {t['directional_groups']} / {t['ranks']} | "
            f"{t['doublets_resolved']} / {t['edges_split_by_propagation']} | {t['conformal']} | "
            f"{t['non_conformal_faces']} | {t['hanging_nodes']} | {t['inverted_hexes']} | "
            f"{t['min_scaled_jacobian']:.4f} | "
            + (f"{o['min_scaled_jacobian']:.4f} |" if "refused" not in o else "refused |"))
    return "\n".join(lines) + "\n"


# --- random target sets --------------------------------------------------------------------------

KINDS = ["uniform", "checkerboard", "isolated", "edge-contact pairs", "vertex-contact pairs",
         "blob"]


def random_targets(n, kind, seed):
    """Target hex ids of an n^3 brick (hex id i + n (j + n k))."""
    g = rnd.Random(seed)
    hid = lambda i, j, k: i + n * (j + n * k)
    cells = [(i, j, k) for k in range(n) for j in range(n) for i in range(n)]
    if kind == "uniform":
        p = g.uniform(0.05, 0.5)
        return [hid(*c) for c in cells if g.random() < p]
    if kind == "checkerboard":
        p = 1.0 if g.random() < 0.3 else 0.5
        return [hid(*c) for c in cells if sum(c) % 2 == 0 and g.random() < p]
    if kind == "isolated":
        return sorted({hid(g.randrange(n), g.randrange(n), g.randrange(n))
                       for _ in range(1 + g.randrange(4))})
    if kind in ("edge-contact pairs", "vertex-contact pairs"):
        out = set()
        for _ in range(1 + g.randrange(3)):
            i, j, k = g.randrange(n - 1), g.randrange(n - 1), g.randrange(n - 1)
            out.add(hid(i, j, k))
            out.add(hid(i + 1, j + 1, k) if kind.startswith("edge") else hid(i + 1, j + 1, k + 1))
        return sorted(out)
    return None  # blob: the selection language's blob:COUNT,SEED


def study_random(sets):
    records = []
    for n in (4, 6):
        mesh = hexrefine.generate("brick", dims=[n, n, n], size=[n, n, n], jitter=0.2, seed=7)
        for s in range(sets // 2):
            kind = KINDS[s % len(KINDS)]
            seed = 1000 * n + s
            targets = random_targets(n, kind, seed)
            if targets is None:
                targets = hexrefine.select(mesh, f"blob:{1 + seed % (n * n)},{seed}")
            base = {"brick": f"{n}^3", "kind": kind, "seed": seed, "targets": len(targets)}
            if len(targets) == 0:
                records.append(dict(base, empty=True))
                continue
            for method, placement in (("selective", "trilinear"), ("selective", "optimized"),
                                      ("sheet", "optimized")):
                r = record_of(mesh, np.asarray(targets), method, placement=placement)
                r.update(base)
                records.append(r)
    return records


def report_random(records):
    variants = [("selective", "trilinear"), ("selective", "optimized"), ("sheet", "optimized")]
    lines = ["# Selective Approach on random target sets", "",
             "Written by `experiments/studies/selective/run.py random` through the Python module; "
             "JSON: `selective_random.json`. Seeded target sets on jittered bricks (4x4x4 and "
             "6x6x6 of unit spacing, interior nodes moved by up to 0.2 of the spacing, brick seed "
             "7): uniform random (5-50 %), checkerboards (whole or half), isolated hexes, pairs "
             "touching along one edge only, pairs touching at one vertex only, and blobs "
             "(`blob:COUNT,SEED`). Each set refined by the Selective Approach with the thesis' "
             "trilinear node placement and with optimized placement (the default), and by the "
             "sheet refiner; every output checked against its input (conformal, no inverted hex, "
             "volume and boundary preserved). \"Refused\" is a RefinementError (`hexrefine "
             "refine` exits 1 and writes nothing): with trilinear placement, a template child "
             "inverted inside a strongly jittered hex.", "",
             "| brick, kind | sets | " + " | ".join(
                 f"{m} {p}: valid / refused / min SJ" for m, p in variants) + " |",
             "|---|---|" + "---|" * len(variants)]
    groups = {}
    for r in records:
        groups.setdefault((r["brick"], r["kind"]), []).append(r)
    totals = {v: [0, 0] for v in variants}
    total_sets = 0
    for (brick, kind), rows in sorted(groups.items()):
        sets = len({r["seed"] for r in rows if not r.get("empty")})
        total_sets += sets
        cells = []
        for m, p in variants:
            mine = [r for r in rows if r.get("method") == m and r["options"]["placement"] == p]
            valid = sum(1 for r in mine if r.get("valid"))
            refused = sum(1 for r in mine if "refused" in r)
            totals[(m, p)][0] += valid
            totals[(m, p)][1] += refused
            low = min((r["min_scaled_jacobian"] for r in mine if r.get("valid")), default=float("nan"))
            cells.append(f"{valid} / {refused} / {low:.3f}")
        lines.append(f"| {brick} {kind} | {sets} | " + " | ".join(cells) + " |")
    lines.append(f"| **total** | {total_sets} | " + " | ".join(
        f"{totals[v][0]} / {totals[v][1]} /" for v in variants) + " |")
    invalid = [r for r in records if "valid" in r and not r["valid"]]
    lines += ["", f"Outputs returned but not valid: {len(invalid)} (a refiner returns only "
              "checked outputs unless an ablation switch is on)."]
    refused = [r for r in records if "refused" in r]
    if refused:
        lines += ["", "## Refused", "", "| brick | kind | seed | method | placement | message |",
                  "|---|---|---|---|---|---|"]
        for r in refused:
            msg = r["refused"].replace("\n", " ").replace("|", "/")
            lines.append(f"| {r['brick']} | {r['kind']} | {r['seed']} | {r['method']} | "
                         f"{r['options']['placement']} | {msg} |")
    return "\n".join(lines) + "\n"


def main():
    global hexrefine
    parser = harness.study_arguments(harness.first_line(__doc__))
    parser.add_argument("studies", nargs="+", choices=["cases", "random"])
    parser.add_argument("--sets", type=int, default=2000, help="random target sets in all")
    args = parser.parse_args()
    hexrefine = harness.import_hexrefine()
    out = pathlib.Path(args.out)
    # The records are hexrefine.check's of each output, not the pipeline report's check: no
    # report schema version applies.
    if "cases" in args.studies:
        records = study_cases()
        harness.write_json_atomic(out / "selective_cases.json",
                                  dict(harness.provenance(), records=records),
                                  final_newline=False)
        harness.write_text_atomic(out / "selective_cases.md", report_cases(records))
    if "random" in args.studies:
        records = study_random(args.sets)
        harness.write_json_atomic(out / "selective_random.json",
                                  dict(harness.provenance(), records=records),
                                  final_newline=False)
        harness.write_text_atomic(out / "selective_random.md", report_random(records))


if __name__ == "__main__":
    main()
