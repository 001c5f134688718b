"""Poisson on a hexrefine mesh with dolfinx 0.5: the SOLVE and ESTIMATE steps of the adaptive loop,
and the true errors against an exact solution.

The problem is -div(grad u) = f in the mesh's domain, u = g (the exact solution) on its whole
boundary, discretised with continuous Lagrange elements of degree 1 (Q1, trilinear on each hex) or
2 (Q2) on the trilinear (isoparametric for Q1) hex geometry. The linear system is solved by
conjugate gradients preconditioned with one algebraic multigrid V-cycle (PETSc GAMG by default, or
hypre BoomerAMG), to a fixed relative tolerance of the preconditioned residual.

Meshes: hexrefine hands over points (n, 3) and hexes (m, 8) in VTK order; dolfinx numbers a hex's
vertices in tensor-product order, so each hex is passed as its VTK nodes [0, 1, 3, 2, 4, 5, 7, 6].
Under MPI the whole mesh lives on rank 0 (hexrefine refines serially) and dolfinx's partitioner
distributes it; per-cell indicators come back to rank 0 by the cells' original indices, which are
hexrefine's hex ids.

The residual estimator (Verfurth's residual estimator for the Poisson problem) on a hex K:

    eta_K^2 = h_K^2 ||f + div grad u_h||_K^2
              + 1/2 sum_{F interior face of K} h_F ||[grad u_h . n]||_F^2

- h_K = |K|^(1/3), the cube root of the hex's volume (SolverOptions.estimator_size 'volume'; or
  'diameter': the largest distance between two of its vertices, UFL's CellDiameter). On the
  transition hexes, long and flat, the diameter overstates the size across the thin direction;
  the volume's cube root keeps the effectivity index steadier (results/adaptive.md, estimator
  variants).
- h_F is the mean of h_K over the two hexes sharing the face F: UFL cannot measure a non-affine
  face of a hex (FacetArea, MaxFacetEdgeLength refuse it).
- div grad u_h is computed exactly (estimator_laplacian True; False drops it): on a trilinear hex
  that is not a parallelepiped the Jacobian varies over the cell, and even on a parallelepiped the
  Q1 space's mixed terms (xi eta, ...) have a non-zero Laplacian. UFL differentiates through the
  inverse Jacobian (a linear function's Laplacian is 0 to rounding on distorted hexes, tested). On
  nested transitions (refining transitions again) this term grows with the distortion rather than
  the error and misleads the marking; on graded meshes it does not (results/adaptive.md).
- [grad u_h . n] = grad u_h(+) . n(+) + grad u_h(-) . n(-) is the jump of the normal derivative;
  every boundary face is a Dirichlet face and has no jump term.
- Each interior face's term is shared half and half by its two hexes (the factor 1/2).

The estimate is (sum_K eta_K^2)^(1/2); its effectivity index is estimate / |u - u_h|_{H^1}.
"""

import dataclasses
import time

import numpy as np
import ufl
from mpi4py import MPI
from petsc4py import PETSc

import dolfinx
import dolfinx.fem.petsc
from dolfinx import fem

#: dolfinx's hex vertex order (tensor product) as positions in the VTK order hexrefine uses.
VTK_TO_DOLFINX = np.array([0, 1, 3, 2, 4, 5, 7, 6])


def mesh_to_dolfinx(comm, points, hexes):
    """A dolfinx mesh of the hex mesh (points (n, 3) float, hexes (m, 8) ids in VTK order) given on
    rank 0 (other ranks pass None for both); dolfinx's graph partitioner distributes the cells.
    Cell c's original index (mesh.topology.original_cell_index) is its row in `hexes`."""
    domain = ufl.Mesh(ufl.VectorElement("Lagrange", ufl.hexahedron, 1))
    if comm.rank == 0:
        cells = np.ascontiguousarray(np.asarray(hexes, dtype=np.int64)[:, VTK_TO_DOLFINX])
        x = np.ascontiguousarray(np.asarray(points, dtype=np.float64))
    else:
        cells = np.empty((0, 8), dtype=np.int64)
        x = np.empty((0, 3), dtype=np.float64)
    return dolfinx.mesh.create_mesh(comm, cells, x, domain)


@dataclasses.dataclass
class SolverOptions:
    """degree: 1 (Q1) or 2 (Q2); pc: 'gamg' or 'hypre'; rtol: CG's relative tolerance.
    The stiffness matrix is integrated with 2 x degree (Gauss, degree + 1 points a direction, exact
    on bricks). quadrature_degree: the right-hand side, the errors and the estimator (the exact
    solution is not a polynomial; 6 is 4 Gauss points a direction). singular_quadrature_degree:
    the errors on the hexes that touch the problem's singular set (a vertex of theirs on it),
    where |grad u|^2 blows up and a tensor Gauss rule converges slowly: on the L-shape's first
    mesh 6 underestimates the H1 error by 2.1 %, 20 (11 points a direction) by 0.1 %."""
    degree: int = 1
    pc: str = "gamg"
    rtol: float = 1e-10
    quadrature_degree: int = 6
    singular_quadrature_degree: int = 20
    estimator_laplacian: bool = True
    estimator_size: str = "volume"  # or "diameter"


@dataclasses.dataclass
class Solution:
    """u_h on `mesh` and how the solve went. dofs: global count (every node, boundary included)."""
    mesh: object
    uh: object
    dofs: int
    iterations: int
    converged_reason: int
    seconds: dict


def _dx(mesh, options):
    return ufl.Measure("dx", domain=mesh, metadata={"quadrature_degree": options.quadrature_degree})


def _dS(mesh, options):
    return ufl.Measure("dS", domain=mesh, metadata={"quadrature_degree": options.quadrature_degree})


def _source(problem, mesh):
    """f as UFL: the problem's expression, a number as a Constant (UFL would fold 0 * v away and
    leave an empty form), or -div(grad u) differentiated by UFL."""
    x = ufl.SpatialCoordinate(mesh)
    f = problem.source(x)
    if f is None:
        return -ufl.div(ufl.grad(problem.exact(x)))
    if isinstance(f, (int, float)):
        return fem.Constant(mesh, PETSc.ScalarType(f))
    return f


def solve(mesh, problem, options=SolverOptions()):
    """Solves the problem's Poisson equation on `mesh` (a dolfinx mesh): assembly, Dirichlet data
    interpolated from the exact solution at the boundary nodes, CG + AMG. Raises RuntimeError if
    CG does not converge."""
    seconds = {}
    start = time.perf_counter()
    V = fem.FunctionSpace(mesh, ("Lagrange", options.degree))
    x = ufl.SpatialCoordinate(mesh)
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    a = fem.form(ufl.inner(ufl.grad(u), ufl.grad(v)) *
                 ufl.dx(metadata={"quadrature_degree": 2 * options.degree}))
    L = fem.form(_source(problem, mesh) * v * _dx(mesh, options))

    tdim = mesh.topology.dim
    mesh.topology.create_connectivity(tdim - 1, tdim)
    boundary_facets = dolfinx.mesh.exterior_facet_indices(mesh.topology)
    boundary_dofs = fem.locate_dofs_topological(V, tdim - 1, boundary_facets)
    g = fem.Function(V)
    g.interpolate(fem.Expression(problem.exact(x), V.element.interpolation_points()))
    bc = fem.dirichletbc(g, boundary_dofs)

    A = fem.petsc.assemble_matrix(a, bcs=[bc])
    A.assemble()
    b = fem.petsc.assemble_vector(L)
    fem.petsc.apply_lifting(b, [a], bcs=[[bc]])
    b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    fem.petsc.set_bc(b, [bc])
    seconds["assemble"] = time.perf_counter() - start

    start = time.perf_counter()
    ksp = PETSc.KSP().create(mesh.comm)
    ksp.setOperators(A)
    ksp.setType("cg")
    ksp.getPC().setType(options.pc)
    if options.pc == "hypre":
        ksp.getPC().setHYPREType("boomeramg")
    ksp.setTolerances(rtol=options.rtol, atol=0.0, max_it=1000)
    uh = fem.Function(V)
    # The boundary values as the initial guess: with set_bc above, b's Dirichlet rows already hold
    # them, so CG starts from a vector that is right on the boundary.
    uh.x.array[:] = 0.0
    fem.petsc.set_bc(uh.vector, [bc])
    ksp.setInitialGuessNonzero(True)
    ksp.solve(b, uh.vector)
    uh.x.scatter_forward()
    reason = ksp.getConvergedReason()
    iterations = ksp.getIterationNumber()
    seconds["krylov"] = time.perf_counter() - start
    ksp.destroy()
    A.destroy()
    b.destroy()
    if reason <= 0:
        raise RuntimeError("CG did not converge (PETSc reason %d after %d iterations)" %
                           (reason, iterations))
    dofs = V.dofmap.index_map.size_global * V.dofmap.index_map_bs
    return Solution(mesh, uh, dofs, iterations, reason, seconds)


def _cell_values(mesh, form_of_test_function):
    """Assembles sum over cells of a form linear in a DG0 test function: one value per owned cell,
    in the mesh's local cell order (ghost contributions added to their owners)."""
    W = fem.FunctionSpace(mesh, ("DG", 0))
    w = ufl.TestFunction(W)
    vector = fem.petsc.assemble_vector(fem.form(form_of_test_function(w)))
    vector.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    owned = mesh.topology.index_map(mesh.topology.dim).size_local
    cell_dofs = W.dofmap.list.array.reshape(-1)[:owned]
    values = vector.array_r[cell_dofs].copy()
    vector.destroy()
    return values


def cell_volume_size(mesh):
    """|K|^(1/3) of every cell, ghosts included, as a DG0 function."""
    W = fem.FunctionSpace(mesh, ("DG", 0))
    vector = fem.petsc.assemble_vector(fem.form(ufl.TestFunction(W) * ufl.dx))
    vector.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    size = fem.Function(W)
    size.x.array[:len(vector.array_r)] = np.cbrt(vector.array_r)
    size.x.scatter_forward()
    vector.destroy()
    return size


def indicators(solution, problem, options=SolverOptions()):
    """eta_K^2 of every owned cell of the solution's mesh (local order); see the module doc."""
    mesh, uh = solution.mesh, solution.uh
    h = ufl.CellDiameter(mesh) if options.estimator_size == "diameter" else cell_volume_size(mesh)
    n = ufl.FacetNormal(mesh)
    residual = _source(problem, mesh)
    if options.estimator_laplacian:
        residual = residual + ufl.div(ufl.grad(uh))
    jump = ufl.jump(ufl.grad(uh), n)
    dx, dS = _dx(mesh, options), _dS(mesh, options)
    return _cell_values(mesh, lambda w: h**2 * residual**2 * w * dx +
                        0.5 * ufl.avg(h) * jump**2 * (w("+") + w("-")) * dS)


def cell_errors(solution, problem, options=SolverOptions()):
    """|u - u_h|_{H^1(K)}^2 of every owned cell (local order): the exact error per cell (an oracle
    indicator, and the field drawn on saved meshes)."""
    mesh, uh = solution.mesh, solution.uh
    e = ufl.grad(uh) - ufl.grad(problem.exact(ufl.SpatialCoordinate(mesh)))
    dx = _error_measure(mesh, problem, options)
    return _cell_values(mesh, lambda w: ufl.inner(e, e) * w * dx)


def _error_measure(mesh, problem, options):
    """dx with quadrature_degree, and singular_quadrature_degree on the owned cells that have a
    vertex on problem.singular (a predicate of points (3, n) -> bool (n,)), if it is set."""
    if problem.singular is None:
        return _dx(mesh, options)
    tdim = mesh.topology.dim
    vertices = dolfinx.mesh.locate_entities(mesh, 0, problem.singular)
    mesh.topology.create_connectivity(0, tdim)
    vertex_cells = mesh.topology.connectivity(0, tdim)
    owned = mesh.topology.index_map(tdim).size_local
    tag = np.zeros(owned, dtype=np.int32)
    for v in vertices:
        cells = vertex_cells.links(v)
        tag[cells[cells < owned]] = 1
    tags = dolfinx.mesh.meshtags(mesh, tdim, np.arange(owned, dtype=np.int32), tag)
    regular = ufl.Measure("dx", domain=mesh, subdomain_data=tags, subdomain_id=0,
                          metadata={"quadrature_degree": options.quadrature_degree})
    singular = ufl.Measure("dx", domain=mesh, subdomain_data=tags, subdomain_id=1,
                           metadata={"quadrature_degree": options.singular_quadrature_degree})
    return regular + singular


def errors(solution, problem, options=SolverOptions()):
    """(|u - u_h|_{H^1}, ||u - u_h||_{L^2}) over the whole mesh (every rank gets both)."""
    mesh, uh = solution.mesh, solution.uh
    exact = problem.exact(ufl.SpatialCoordinate(mesh))
    dx = _error_measure(mesh, problem, options)
    e = ufl.grad(uh) - ufl.grad(exact)
    h1 = fem.assemble_scalar(fem.form(ufl.inner(e, e) * dx))
    l2 = fem.assemble_scalar(fem.form((uh - exact)**2 * dx))
    h1, l2 = mesh.comm.allreduce(np.array([h1, l2]), op=MPI.SUM)
    return float(np.sqrt(h1)), float(np.sqrt(l2))


def gather_by_original_cell(mesh, values, hex_count):
    """Rank 0: the per-cell `values` (owned cells, local order) of every rank as one array of
    `hex_count` values indexed by hexrefine hex id; other ranks: None."""
    owned = mesh.topology.index_map(mesh.topology.dim).size_local
    original = np.asarray(mesh.topology.original_cell_index[:owned], dtype=np.int64)
    parts = mesh.comm.gather((original, np.asarray(values)), root=0)
    if mesh.comm.rank != 0:
        return None
    out = np.full(hex_count, np.nan)
    for ids, vals in parts:
        out[ids] = vals
    if np.isnan(out).any():
        raise RuntimeError("gather_by_original_cell: %d hexes got no value" % np.isnan(out).sum())
    return out
