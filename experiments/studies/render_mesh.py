#!/usr/bin/python3
"""Draws the boundary quads of a hex mesh, coloured by template, as a PNG.

usage: experiments/studies/render_mesh.py MESH OUT.png [--title T] [--field template_tag] [--elev 25 --azim -60]

MESH is anything meshio reads with hexahedron cells (e.g. the .vtu files `hexrefine run` writes
for cases with "save_mesh"). Boundary quads are the hex faces used by exactly one hex; each is
coloured by the integer cell field (default template_tag, as algorithms/refiners/refiner.hpp numbers it)
of its hex and drawn as matplotlib 3D polygons. Without the field every quad is grey.
"""

import os
import pathlib
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import meshio  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # noqa: E402

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import harness  # noqa: E402

# TemplateTag of algorithms/refiners/refiner.hpp.
TEMPLATE_NAMES = {0: "untouched", 1: "1-27", 2: "1-13", 3: "1-5", 4: "1-4", 5: "1-3",
                  6: "1-3-adj1", 7: "1-3-adj2", 8: "directional", 9: "sheet"}
TEMPLATE_COLOURS = {0: "#d9d9d9", 1: "#1f77b4", 2: "#ff7f0e", 3: "#2ca02c", 4: "#9467bd",
                    5: "#d62728", 6: "#8c564b", 7: "#e377c2", 8: "#bcbd22", 9: "#17becf"}

# Faces of a hex in the VTK order, each listed counter-clockwise seen from outside.
HEX_FACES = np.array([[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4],
                      [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]])


def hexes_and_field(mesh, field):
    """(hexes (n, 8), per-hex field values or None) from the hexahedron blocks of `mesh`."""
    hexes, values = [], []
    for i, block in enumerate(mesh.cells):
        if block.type != "hexahedron":
            continue
        hexes.append(block.data)
        data = mesh.cell_data.get(field)
        values.append(np.asarray(data[i]).reshape(-1) if data is not None else None)
    if not hexes:
        raise ValueError("no hexahedron cells")
    field_values = None if any(v is None for v in values) else np.concatenate(values)
    return np.concatenate(hexes), field_values


def boundary_quads(hexes):
    """(quads (m, 4) node ids, owning hex of each): the faces used by exactly one hex."""
    faces = hexes[:, HEX_FACES].reshape(-1, 4)
    owner = np.repeat(np.arange(len(hexes)), 6)
    keys = np.sort(faces, axis=1)
    _, inverse, counts = np.unique(keys, axis=0, return_inverse=True, return_counts=True)
    once = counts[inverse.reshape(-1)] == 1
    return faces[once], owner[once]


def render(path, out, title=None, field="template_tag", elev=25.0, azim=-60.0):
    mesh = meshio.read(path)
    hexes, values = hexes_and_field(mesh, field)
    quads, owner = boundary_quads(hexes)
    points = np.asarray(mesh.points, dtype=float)
    polygons = points[quads]
    if values is not None:
        tags = values[owner].astype(int)
        colours = [TEMPLATE_COLOURS.get(t, "#000000") for t in tags]
        present = sorted(set(tags.tolist()))
    else:
        colours, present = ["#c0c0c0"] * len(quads), []
    fig = plt.figure(figsize=(7, 6))
    ax = fig.add_subplot(111, projection="3d")
    ax.add_collection3d(Poly3DCollection(polygons, facecolors=colours, edgecolors="#202020",
                                         linewidths=0.15))
    lo, hi = points.min(axis=0), points.max(axis=0)
    centre, half = (lo + hi) / 2, (hi - lo).max() / 2 or 1.0
    for setter, c in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), centre):
        setter(c - half, c + half)
    ax.set_box_aspect((1, 1, 1))
    ax.view_init(elev=elev, azim=azim)
    ax.set_axis_off()
    if present:
        ax.legend(handles=[Patch(color=TEMPLATE_COLOURS.get(t, "#000000"),
                                 label=TEMPLATE_NAMES.get(t, str(t))) for t in present],
                  loc="upper left", fontsize=8)
    ax.set_title(title or os.path.basename(path), fontsize=10)
    fig.tight_layout()
    harness.savefig_atomic(fig, out, 110)


def main():
    parser = harness.study_arguments(harness.first_line(__doc__), out=None)
    parser.add_argument("mesh")
    parser.add_argument("out")
    parser.add_argument("--title")
    parser.add_argument("--field", default="template_tag")
    parser.add_argument("--elev", type=float, default=25.0)
    parser.add_argument("--azim", type=float, default=-60.0)
    args = parser.parse_args()
    try:
        render(args.mesh, args.out, args.title, args.field, args.elev, args.azim)
    except (OSError, ValueError, KeyError) as e:
        print("render_mesh.py: error: %s: %s" % (args.mesh, e), file=sys.stderr)
        sys.exit(2)
    except meshio.ReadError as e:
        print("render_mesh.py: error: %s: %s" % (args.mesh, e), file=sys.stderr)
        sys.exit(2)


if __name__ == "__main__":
    main()
