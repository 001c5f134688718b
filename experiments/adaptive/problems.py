"""The adaptive study's model problems: a domain (an initial hexrefine mesh), an exact solution u as
a UFL expression of the spatial coordinate, and f = -div(grad u) in closed form (0 where u is
harmonic), so the true error is measured and not only the estimate. Dirichlet data g = u on the
whole boundary.

- lshape: the thesis' L-shape as a PDE. The prism ((-1,1)^2 minus the quadrant x > 0, y < 0) x
  (0,1), 192 hexes (4 a unit length), u = r^(2/3) sin(2 theta/3) with theta from the positive x
  axis in [0, 3 pi/2], f = 0: the gradient is singular along the whole re-entrant edge x = y = 0.
- rockerarm: a steep interior layer on the real mesh rockerarm.mesh (10,600 hexes, 12,751 nodes):
  u = atan(alpha (|x - c| - r0)), a spherical shell of width about 1/alpha (alpha = 5, c outside
  the part, r0 so the shell crosses the arm's middle), curved against the mesh's sheets.
- fichera: the Fichera corner (-1,1)^3 minus [0,1)^3 (its re-entrant vertex at the origin), 189
  hexes (3 a unit length), u = |x|^(1/2), f = -3/4 |x|^(-3/2): a point singularity at the vertex.
- smooth: the unit cube, 3 hexes a side, u = sin(pi x) sin(pi y) sin(pi z), f = 3 pi^2 u (for the
  convergence test).
"""

import dataclasses
import math
import os
import pathlib

import numpy as np
import ufl

import hexrefine


@dataclasses.dataclass
class Problem:
    """name, a one-line description, initial_mesh() -> hexrefine.HexMesh, exact(x) -> UFL
    expression of the SpatialCoordinate x, source(x) -> f as a UFL expression, a number, or None
    for -div(grad(exact)) differentiated by UFL; singular(points (3, n)) -> bool (n,): the
    points where grad u blows up (the errors integrate the hexes touching them more finely), or
    None."""
    name: str
    description: str
    initial_mesh: object
    exact: object
    source: object
    singular: object = None


def structured_hex_mesh(lower, upper, cells, keep=None):
    """A hexrefine mesh of the box lower..upper (3 floats each) split into cells[0] x cells[1] x
    cells[2] bricks, minus the bricks whose centre fails keep(centre (3,)) -> bool; nodes no kept
    brick uses are dropped. Hexes in VTK order, positively oriented."""
    lower, upper = np.asarray(lower, float), np.asarray(upper, float)
    nx, ny, nz = cells
    axes = [np.linspace(lower[d], upper[d], cells[d] + 1) for d in range(3)]
    X, Y, Z = np.meshgrid(*axes, indexing="ij")
    points = np.c_[X.ravel(), Y.ravel(), Z.ravel()]

    def node(i, j, k):
        return (i * (ny + 1) + j) * (nz + 1) + k

    i, j, k = [a.ravel() for a in np.meshgrid(np.arange(nx), np.arange(ny), np.arange(nz),
                                             indexing="ij")]
    hexes = np.stack([node(i, j, k), node(i + 1, j, k), node(i + 1, j + 1, k), node(i, j + 1, k),
                      node(i, j, k + 1), node(i + 1, j, k + 1), node(i + 1, j + 1, k + 1),
                      node(i, j + 1, k + 1)], axis=1)
    if keep is not None:
        centres = points[hexes].mean(axis=1)
        hexes = hexes[np.array([bool(keep(c)) for c in centres])]
    used = np.unique(hexes)
    renumber = np.full(len(points), -1, dtype=np.int64)
    renumber[used] = np.arange(len(used))
    return hexrefine.HexMesh(points[used], renumber[hexes])


def lshape_mesh(cells_per_unit=4):
    n = cells_per_unit
    return structured_hex_mesh([-1, -1, 0], [1, 1, 1], [2 * n, 2 * n, n],
                               keep=lambda c: not (c[0] > 0 and c[1] < 0))


def lshape_exact(x):
    """r^(2/3) sin(2 theta/3), theta in [0, 3 pi/2]. atan2 gives (-pi, pi]; a point in the cut-away
    quadrant (-pi/2 < atan2 < 0) can only be a boundary node a rounding error off the face y = 0
    (x > 0) or x = 0 (y < 0): it is clamped to the nearer face, theta = 0 or 3 pi/2. A plain
    mod(atan2, 2 pi) would give such a node theta near 2 pi and wrong Dirichlet data."""
    r = ufl.sqrt(x[0]**2 + x[1]**2)
    a = ufl.atan_2(x[1], x[0])
    theta = ufl.conditional(
        ufl.ge(a, 0.0), a,
        ufl.conditional(ufl.le(a, -math.pi / 2), a + 2 * math.pi,
                        ufl.conditional(ufl.gt(a, -math.pi / 4), 0.0, 1.5 * math.pi)))
    return r**(2.0 / 3.0) * ufl.sin(2.0 * theta / 3.0)


#: The layer's parameters on rockerarm.mesh (its bounding box is about (-20, -12, -39) to
#: (20, 12, 39), hexes about 1.3 across): centre outside the part beside its middle, radius so the
#: shell cuts the arm obliquely, width 1/alpha = 0.2.
LAYER_CENTRE = (25.0, 15.0, 0.0)
LAYER_RADIUS = 30.0
LAYER_ALPHA = 2.0


def shared_mesh_path(name):
    """A file of the shared meshes folder: $HEXREFINE_SHARED_DIR, else ../shared beside the
    repository."""
    shared = os.environ.get("HEXREFINE_SHARED_DIR")
    if shared is None:
        shared = pathlib.Path(__file__).resolve().parents[3] / "shared"
    return str(pathlib.Path(shared) / "meshes" / name)


def layer_exact(x, centre=LAYER_CENTRE, radius=LAYER_RADIUS, alpha=LAYER_ALPHA):
    rho = ufl.sqrt(sum((x[d] - centre[d])**2 for d in range(3)))
    return ufl.atan(alpha * (rho - radius))


def layer_source(x, centre=LAYER_CENTRE, radius=LAYER_RADIUS, alpha=LAYER_ALPHA):
    """-Laplacian of atan(s), s = alpha (rho - r0), radial in 3D: -(u'' + 2 u' / rho), with
    u' = alpha / (1 + s^2) and u'' = -2 alpha^2 s / (1 + s^2)^2."""
    rho = ufl.sqrt(sum((x[d] - centre[d])**2 for d in range(3)))
    s = alpha * (rho - radius)
    du = alpha / (1 + s**2)
    d2u = -2 * alpha**2 * s / (1 + s**2)**2
    return -(d2u + 2 * du / rho)


def fichera_mesh(cells_per_unit=3):
    n = cells_per_unit
    return structured_hex_mesh([-1, -1, -1], [1, 1, 1], [2 * n] * 3,
                               keep=lambda c: not (c > 0).all())


def fichera_exact(x):
    return (x[0]**2 + x[1]**2 + x[2]**2)**0.25


def fichera_source(x):
    return -0.75 * (x[0]**2 + x[1]**2 + x[2]**2)**(-0.75)


def smooth_exact(x):
    return ufl.sin(math.pi * x[0]) * ufl.sin(math.pi * x[1]) * ufl.sin(math.pi * x[2])


PROBLEMS = {
    "lshape": Problem("lshape", "L-shaped prism, u = r^(2/3) sin(2 theta/3), singular edge",
                      lshape_mesh, lshape_exact, lambda x: 0.0,
                      lambda p: (np.abs(p[0]) < 1e-10) & (np.abs(p[1]) < 1e-10)),
    "rockerarm": Problem("rockerarm", "rockerarm.mesh, u = atan(5 (|x - c| - 30)), a curved layer",
                         lambda: hexrefine.read(shared_mesh_path("rockerarm.mesh")),
                         layer_exact, layer_source),
    "fichera": Problem("fichera", "Fichera corner, u = |x|^(1/2), singular vertex",
                       fichera_mesh, fichera_exact, fichera_source,
                       lambda p: (np.abs(p) < 1e-10).all(axis=0)),
    "smooth": Problem("smooth", "unit cube, u = sin(pi x) sin(pi y) sin(pi z)",
                      lambda: structured_hex_mesh([0, 0, 0], [1, 1, 1], [3, 3, 3]),
                      smooth_exact, lambda x: 3 * math.pi**2 * smooth_exact(x)),
}
