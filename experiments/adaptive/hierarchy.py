"""Graded adaptive refinement by levels: the mesh is rebuilt from the initial mesh by one hexrefine
call per level, so that every level's transition templates land in hexes that are full 3 x 3 x 3
children of the level before and no transition is ever split by a transition again.

Why: refining the marked hexes of the current mesh again and again puts transition templates
(1-13, 1-5, 1-4, 1-3) into hexes that are themselves transition children; each time the minimum
scaled Jacobian falls by about the template's factor (on the L-shape: 1.0, 0.47, 0.13, 0.017,
0.006 in four steps) until hexrefine refuses the refinement. This is the adaptive loop's form of
the thesis' pass-buffer rule (algorithms/refiners/refiner.hpp, PassBuffer::layer; results/buffer_rules.md),
with red-green refinement's rule that a marked transition hex refines its regular parent instead.

The state is the initial mesh M_0 and a set of marks: points p with a level d(p) they want. A hex
is *regular at level l* if it descends from an initial hex by l full 1-27 splits (untouched or
27 children each time), a *transition hex of level l* if it is a child of another split of a
regular level-l hex. Marking a hex h of the current mesh adds the mark (centroid of h, level(h) +
1), where a transition hex has its regular parent's level: a marked transition refines its
parent (red-green's rule: the green closure is removed, the parent refined red).

Rebuilding: M_{l+1} = refine(M_l, T_l) with, C_j the regular level-l hexes that contain a mark
with d(p) - l >= j and ring(S) the hexes sharing a node with S,

    T_l = C_1  u  ring(C_2)  u  ring(ring(C_3)).

Why these rings: a hex X of T_{l+1} has its node-neighbours among the children of parent(X) and
of parent(X)'s node-neighbours, so the level-(l+1) transitions (placed in hexes sharing a node
with T_{l+1}) land in full children of level l if T_l contains ring(parents(T_{l+1})). With T_l
containing r(j) rings around C_j, parents of r(j) level-(l+1) rings lie within ceil(r(j)/3)
level-l rings, so r(j + 1) = 1 + ceil(r(j) / 3) with r(1) = 0: 0, 1, 2, 2, ... (two rings
suffice at any depth). The rings grade the mesh: each level's refined region is at least one
coarser hex wider than the next one's.

Each level's (T_l, M_{l+1}) is cached and reused while T_l is unchanged, so a step rebuilds only
from the first level its new marks change.
"""

import numpy as np

import hexrefine

#: Reference-cube corners of the hex nodes in VTK order.
HEX_CORNERS = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0],
                        [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], dtype=float)


def hex_reference_coordinates(corners, points, iterations=12):
    """The reference coordinates xi in [0, 1]^3 (n, 3) of points (n, 3) in trilinear hexes with
    corners (n, 8, 3) (VTK order), by Newton's method from the centre; exact for bricks and
    parallelepipeds, converged to rounding for the mildly curved hexes here."""
    xi = np.full((len(points), 3), 0.5)
    c = HEX_CORNERS
    for _ in range(iterations):
        # Trilinear shape functions and their derivatives at xi.
        f = np.where(c[None, :, :] == 1, xi[:, None, :], 1 - xi[:, None, :])  # (n, 8, 3)
        df = np.where(c[None, :, :] == 1, 1.0, -1.0)                         # (1, 8, 3)
        shape = f.prod(axis=2)                                               # (n, 8)
        grads = np.empty((len(points), 8, 3))
        grads[:, :, 0] = df[:, :, 0] * f[:, :, 1] * f[:, :, 2]
        grads[:, :, 1] = f[:, :, 0] * df[:, :, 1] * f[:, :, 2]
        grads[:, :, 2] = f[:, :, 0] * f[:, :, 1] * df[:, :, 2]
        residual = np.einsum("ni,nik->nk", shape, corners) - points
        jacobian = np.einsum("nik,nij->nkj", corners, grads)
        xi = xi - np.linalg.solve(jacobian, residual[:, :, None])[:, :, 0]
    return xi


def hex_children_grid_cells(parents, xi):
    """The cell (0..26, (i * 3 + j) * 3 + k) of the 3 x 3 x 3 split each child occupies, from the
    reference coordinates xi (n, 3) of the children's centroids in their parent (parents (n,),
    27 children each): by rank within the parent, the 9 smallest xi_x are i = 0, and so on per
    axis. Unlike rounding 3 xi, ranks survive smoothing, which moves the children's nodes off the
    thirds."""
    by_x = np.lexsort((xi[:, 0], parents)).reshape(-1, 27)
    if len(by_x) * 27 != len(parents) or (parents[by_x] != parents[by_x[:, :1]]).any():
        raise RuntimeError("graded refinement: a full split without 27 children")
    # i: rank of xi_x among the parent's 27 children (in nines); j: of xi_y among the 9 with the
    # same i (in threes); k: of xi_z among the 3 with the same (i, j).
    i = np.empty(len(parents), dtype=np.int64)
    i[by_x] = np.repeat(np.arange(3), 9)
    by_y = np.lexsort((xi[:, 1], i, parents)).reshape(-1, 9)
    j = np.empty_like(i)
    j[by_y] = np.repeat(np.arange(3), 3)
    by_z = np.lexsort((xi[:, 2], j, i, parents)).reshape(-1, 3)
    k = np.empty_like(i)
    k[by_z] = np.arange(3)
    return (i * 3 + j) * 3 + k


def hexes_touching(mesh_hexes, point_count, chosen):
    """Bool mask (m,): the hexes sharing a node with a chosen hex (chosen ones included)."""
    touched = np.zeros(point_count, dtype=bool)
    touched[mesh_hexes[chosen].ravel()] = True
    return touched[mesh_hexes].any(axis=1)


class _Level:
    """M_l with, per hex, its level, whether it is regular (full splits only) and its initial
    ancestor; targets and next (the level above) once refined."""

    def __init__(self, mesh, level, regular, root):
        self.mesh, self.level, self.regular, self.root = mesh, level, regular, root
        self.hexes = mesh.hexes
        self.points = mesh.points
        self.targets, self.next, self.report, self.seconds = None, None, None, 0.0


class GradedRefinement:
    """The graded mesh of an adaptive loop (see the module doc). refine_kwargs go to every
    hexrefine.refine call (method, placement, smooth)."""

    def __init__(self, initial, refine_kwargs):
        n = initial.hex_count
        self.base = _Level(initial, np.zeros(n, dtype=np.int64), np.ones(n, dtype=bool),
                           np.arange(n, dtype=np.int64))
        self.refine_kwargs = refine_kwargs
        self.mark_points = np.empty((0, 3))
        self.mark_levels = np.empty(0, dtype=np.int64)
        self.mark_roots = np.empty(0, dtype=np.int64)
        self.current = self.base
        self.refine_calls = 0

    @property
    def mesh(self):
        return self.current.mesh

    def mark(self, hex_ids):
        """Adds the marks of these hexes of the current mesh (their centroids, level + 1)."""
        top = self.current
        ids = np.asarray(hex_ids, dtype=np.int64)
        self.mark_points = np.vstack([self.mark_points, top.points[top.hexes[ids]].mean(axis=1)])
        self.mark_levels = np.concatenate([self.mark_levels, top.level[ids] + 1])
        self.mark_roots = np.concatenate([self.mark_roots, top.root[ids]])

    def rebuild(self):
        """Rebuilds the mesh from the initial one for the marks so far, reusing the cached
        levels whose targets are unchanged. Returns (mesh, the last refinement's report or None
        when nothing was refined, the targets of every level, the levels actually refined).
        RefinementError if hexrefine refuses a level's refinement."""
        level = self.base
        location = self.mark_roots.copy()
        l, targets_per_level, refined_levels = 0, [], 0
        report = None
        while True:
            need = self.mark_levels - l
            if not (need > 0).any():
                break
            targets = self._targets(level, location, need)
            targets_per_level.append(len(targets))
            if level.next is None or not np.array_equal(level.targets, targets):
                self._refine(level, targets)
                refined_levels += 1
            report = level.report
            location = self._locate(level, location, need)
            level = level.next
            l += 1
        self.current = level
        return level.mesh, report, targets_per_level, refined_levels

    def _targets(self, level, location, need):
        chosen = np.zeros(level.mesh.hex_count, dtype=bool)
        chosen[location[need >= 1]] = True
        for rings, depth in ((1, 2), (2, 3)):
            inner = np.zeros_like(chosen)
            inner[location[need >= depth]] = True
            for _ in range(rings):
                inner = hexes_touching(level.hexes, level.mesh.point_count, inner)
            chosen |= inner
        targets = np.flatnonzero(chosen)
        if not level.regular[targets].all():
            # The rings of the level below keep this from happening (module doc); if a method
            # spread its transitions further, say so rather than nest them silently.
            raise RuntimeError("graded refinement: %d of %d targets at level %d are transition "
                               "hexes" % ((~level.regular[targets]).sum(), len(targets),
                                          int(level.level[targets].min())))
        return targets

    def _refine(self, level, targets):
        refined, report = hexrefine.refine(level.mesh, targets, **self.refine_kwargs)
        self.refine_calls += 1
        parents = refined.attributes["parent_hex"].astype(np.int64)
        counts = np.bincount(parents, minlength=level.mesh.hex_count)
        full = counts[parents] == 27
        level.targets = targets
        level.report = report
        level.next = _Level(refined, level.level[parents] + full,
                            level.regular[parents] & (full | (counts[parents] == 1)),
                            level.root[parents])

    def _locate(self, level, location, need):
        """The hexes of the level above that contain the marks still needing a level: the full
        child of their hex there, by the reference coordinates of the mark and of the children's
        centroids in the parent hex."""
        location = location.copy()
        moving = np.flatnonzero(need >= 2)
        if len(moving) == 0:
            return location
        above = level.next
        parents = above.mesh.attributes["parent_hex"].astype(np.int64)
        counts = np.bincount(parents, minlength=level.mesh.hex_count)
        children = np.flatnonzero(counts[parents] == 27)
        child_parents = parents[children]
        child_xi = hex_reference_coordinates(
            level.points[level.hexes[child_parents]],
            above.points[above.hexes[children]].mean(axis=1))
        child_key = child_parents * 27 + hex_children_grid_cells(child_parents, child_xi)
        by_key = dict(zip(child_key.tolist(), children.tolist()))
        if len(by_key) != len(children):
            raise RuntimeError("graded refinement: two children of a hex at the same place")
        hexes = location[moving]
        xi = hex_reference_coordinates(level.points[level.hexes[hexes]], self.mark_points[moving])
        cell = np.clip(np.floor(xi * 3), 0, 2).astype(np.int64)
        keys = hexes * 27 + (cell[:, 0] * 3 + cell[:, 1]) * 3 + cell[:, 2]
        location[moving] = [by_key[k] for k in keys.tolist()]
        return location
