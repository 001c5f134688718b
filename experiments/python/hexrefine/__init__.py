"""hexrefine: conformal refinement of unstructured all-hexahedral meshes, from Python.

The same library as the `hexrefine` command line (no second implementation): the Selective
Approach (Parrish) and Harris-style sheet refinement behind one pipeline (plan, apply, node
placement, check, smooth, check).

    import hexrefine
    mesh = hexrefine.read("part.mesh")          # or hexrefine.generate("brick", dims=[10, 10, 10])
    targets = hexrefine.select(mesh, "sphere:0,0,0,5")
    refined, report = hexrefine.refine(mesh, targets, method="selective")
    quality = hexrefine.quality(refined)            # numpy array, one value per hex
    refined.attributes["parent_hex"]                # the input hex of every output hex

Arrays: points float64 (n, 3); hexes int32 (m, 8) in VTK/Exodus vertex order; attributes
{name: int32 (m,)}. Bad input raises ValueError naming the hex, node, file or spec; a refinement
that cannot be carried out raises RefinementError (a RuntimeError). Long calls release the GIL.
meshio is optional: it is imported only by from_meshio and to_meshio.
"""

import inspect

from . import _hexrefine
from ._hexrefine import (HexMesh, RefinementError, check, generate, methods, quality, read,
                         refine_options, run, select, write)

__all__ = ["HexMesh", "RefinementError", "check", "from_meshio", "generate", "methods", "quality", "read",
           "refine", "refine_options", "run", "select", "to_meshio", "write"]


def refine(mesh, targets, method="selective", threads=1, **options):
    # The signature and the docstring are set below from the options table.
    return _hexrefine.refine(mesh, targets, method, threads, **options)


def _refine_signature_and_doc():
    """refine's keywords and their help, from the pipeline's one table of options
    (algorithms/pipeline/pipeline_options_table.hpp, through refine_options()): a default that
    depends on another option (placement) shows as None."""
    parameter = inspect.Parameter
    parameters = [parameter("mesh", parameter.POSITIONAL_OR_KEYWORD),
                  parameter("targets", parameter.POSITIONAL_OR_KEYWORD),
                  parameter("method", parameter.POSITIONAL_OR_KEYWORD, default="selective"),
                  parameter("threads", parameter.POSITIONAL_OR_KEYWORD, default=1)]
    lines = [_hexrefine.refine.__doc__.split("\n\n", 1)[-1].strip(), "", "Options:"]
    for row in refine_options():
        parameters.append(parameter(row["key"], parameter.KEYWORD_ONLY, default=row["default"]))
        lines.append("  %s (%s): %s" % (row["key"], row["type"], row["help"]))
    return inspect.Signature(parameters), "\n".join(lines)


refine.__signature__, refine.__doc__ = _refine_signature_and_doc()


def from_meshio(m):
    """A HexMesh from a meshio.Mesh: its "hexahedron" cells (other cell types are refused, as the
    readers refuse volume elements that are not linear hexes; surface cells are skipped) and
    their integer cell data as attributes."""
    import numpy as np

    hexes, attributes = [], {}
    for k, block in enumerate(m.cells):
        if block.type == "hexahedron":
            hexes.append(np.asarray(block.data))
            for name, data in m.cell_data.items():
                values = np.asarray(data[k])
                if values.ndim == 1 and np.issubdtype(values.dtype, np.integer):
                    attributes.setdefault(name, []).append(values)
        elif block.type in ("tetra", "wedge", "pyramid", "hexahedron20", "hexahedron27"):
            raise ValueError("from_meshio: cell block %d is %s: only linear hexahedra are "
                             "supported" % (k, block.type))
    if not hexes:
        raise ValueError("from_meshio: the mesh has no hexahedron cells")
    attributes = {name: np.concatenate(parts) for name, parts in attributes.items()
                  if len(parts) == len(hexes)}
    return HexMesh(np.asarray(m.points, dtype=float)[:, :3], np.concatenate(hexes), attributes)


def to_meshio(mesh):
    """A meshio.Mesh with one "hexahedron" block and the attributes as integer cell data."""
    import meshio

    return meshio.Mesh(mesh.points, [("hexahedron", mesh.hexes)],
                       cell_data={name: [values] for name, values in mesh.attributes.items()})
