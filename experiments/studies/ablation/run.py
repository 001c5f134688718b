#!/usr/bin/env python3
"""Ablation of the Selective Approach's ranking system and propagation scheme (Parrish, ch. 4),
run through the Python module over seeded random target sets.

For every mesh, seed and target fraction, the selective refiner runs four ways (ranking on/off x
propagation on/off) on the same targets; the checker counts the non-conformal faces each leaves
and the hexes it makes. The full method must leave none; without propagation the directional
cells leave faces non-conformal (the thesis' motivation for the scheme); without ranking the
result stays conformal but grows. Writes the records as JSON (with the provenance) and a
two-panel plot.

    python3 experiments/studies/ablation/run.py \
        --seeds 10 --json results/ablation.json --plot results/plots/ablation.png

Optimized placement is the default (trilinear placement inverts hexes of rockerarm's distorted
parents, which the pipeline refuses); the conformity counts do not depend on placement.
"""

import os
import pathlib
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent.parent))
import harness  # noqa: E402

hexrefine = None  # the Python module, imported by main() (harness.import_hexrefine)

VARIANTS = [(True, True, "full"), (False, True, "no ranking"), (True, False, "no propagation"),
            (False, False, "neither")]


def meshes(shared, quick):
    yield "brick 12^3", hexrefine.generate("brick", dims=[12, 12, 12])
    if quick:
        return
    yield "gear", hexrefine.generate("gear")
    rockerarm = pathlib.Path(shared) / "meshes" / "rockerarm.mesh"
    if rockerarm.exists():
        yield "rockerarm", hexrefine.read(str(rockerarm))


def run(args, versions):
    """The records of every mesh, seed and variant; the schema versions of the reports read go
    into `versions` (a set)."""
    records = []
    for name, mesh in meshes(args.shared, args.quick):
        for seed in range(args.seeds):
            targets = hexrefine.select(mesh, f"random:{args.fraction},{seed}")
            for ranking, propagation, label in VARIANTS:
                refined, report = hexrefine.refine(mesh, targets, ranking=ranking,
                                                   propagation=propagation,
                                                   placement=args.placement)
                versions.add(harness.report_schema_version(report))
                check = harness.report_output_check(report)
                records.append({"mesh": name, "seed": seed, "targets": int(len(targets)),
                                "variant": label, "ranking": ranking, "propagation": propagation,
                                "hexes": refined.hex_count,
                                "non_conformal_faces": check["non_conformal_faces"],
                                "valid": check["valid"],
                                "min_scaled_jacobian": check["min_scaled_jacobian"]})
        full = [r for r in records if r["mesh"] == name and r["variant"] == "full"]
        if any(r["non_conformal_faces"] for r in full):
            sys.exit(f"ablation: the full method left non-conformal faces on {name}")
    return records


def plot(records, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = list(dict.fromkeys(r["mesh"] for r in records))
    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    width = 0.8 / len(VARIANTS)
    for k, (_, _, label) in enumerate(VARIANTS):
        for panel, key in ((0, "non_conformal_faces"), (1, "hexes")):
            means, lows, highs = [], [], []
            for name in names:
                values = [r[key] for r in records if r["mesh"] == name and r["variant"] == label]
                if key == "hexes":  # relative to the full method on the same seed
                    base = [r[key] for r in records if r["mesh"] == name and r["variant"] == "full"]
                    values = [v / b for v, b in zip(values, base)]
                mean = sum(values) / len(values)
                means.append(mean)
                lows.append(mean - min(values))
                highs.append(max(values) - mean)
            xs = [i + (k - 1.5) * width for i in range(len(names))]
            axes[panel].bar(xs, means, width, yerr=[lows, highs], label=label, capsize=2)
    axes[0].set_ylabel("non-conformal faces left (mean, min-max over seeds)")
    axes[1].set_ylabel("hexes relative to the full method")
    axes[1].set_ylim(bottom=0.95)
    for ax in axes:
        ax.set_xticks(range(len(names)), names)
    axes[0].legend()
    fig.suptitle("Selective Approach ablation: ranking system and propagation scheme")
    fig.tight_layout()
    harness.savefig_atomic(fig, path, 110)


def main():
    global hexrefine
    parser = harness.study_arguments(harness.first_line(__doc__), out=None)
    parser.add_argument("--seeds", type=int, default=10, help="random target sets per mesh")
    parser.add_argument("--fraction", type=float, default=0.05, help="fraction of hexes targeted")
    parser.add_argument("--placement", default="optimized", choices=["trilinear", "optimized"])
    parser.add_argument("--shared", default=os.environ.get("HEXREFINE_SHARED_DIR", str(harness.SHARED)))
    parser.add_argument("--quick", action="store_true", help="the brick only (the tests' run)")
    parser.add_argument("--json", help="write the records here")
    parser.add_argument("--plot", help="write the plot here (PNG)")
    args = parser.parse_args()
    hexrefine = harness.import_hexrefine()
    versions = set()
    records = run(args, versions)
    if args.json:
        harness.write_json_atomic(args.json, dict(
            harness.provenance(schema_version=versions), fraction=args.fraction,
            placement=args.placement, records=records), final_newline=False)
    if args.plot:
        plot(records, args.plot)
    for name in dict.fromkeys(r["mesh"] for r in records):
        for _, _, label in VARIANTS:
            rows = [r for r in records if r["mesh"] == name and r["variant"] == label]
            print(f"{name:12s} {label:15s} non-conformal faces "
                  f"{sum(r['non_conformal_faces'] for r in rows) / len(rows):8.1f}  hexes "
                  f"{sum(r['hexes'] for r in rows) / len(rows):9.1f}")


if __name__ == "__main__":
    main()
