"""The obstacles of extended translations (Wilson & Latombe 1992, "Extended translations"):
per part its convex bodies and bounding sphere, per ordered pair of parts the open cones
of directions along which one blocks the other (one per pair of convex bodies, the
grown obstacle ``Q ⊕ (−P)`` of :mod:`assemblykit.geometry.minkowski`) and the
translation that backs one out of the other when they share a volume the interference
policy counts as touching (:func:`assemblykit.geometry.interference.interference_threshold`,
:func:`assemblykit.geometry.settling.settle`).

:mod:`assemblykit.blocking.extended` decides blocking with them and
:mod:`assemblykit.blocking.free_cones` builds exact blocked sets from them.
"""

from __future__ import annotations

import itertools
import weakref
from typing import cast

import numpy as np
from numpy.typing import NDArray

from assemblykit.blocking.lattice import lattice_cells
from assemblykit.geometry.booleans import manifold3d
from assemblykit.geometry.interference import interference_threshold, part_solid
from assemblykit.geometry.minkowski import blocking_cone, convex_bodies
from assemblykit.geometry.occlusion import hull_vertices, triangle_spheres
from assemblykit.geometry.settling import layer_thickness, settle
from assemblykit.model.assembly import Assembly, AssemblyLike
from assemblykit.tolerance import ModelTolerance, Tolerance


def of_meshes(assembly: AssemblyLike) -> Assembly:
    """``assembly``, whose parts must be in space (``dimension`` 3: an
    :class:`~assemblykit.model.assembly.Assembly` of meshes): the obstacles of extended
    translations in 3D are built from the parts' meshes (polygon assemblies have exact
    planar terms, :mod:`assemblykit.blocking.planar`)."""
    assert assembly.dimension == 3, f"no meshes in a {type(assembly).__name__}"
    return cast("Assembly", assembly)


WITNESSES_KEPT = 8
"""How many pairs of faces that showed a pair of parts blocking are kept for it: two
faces show a block over a cone of directions, and a search that visits directions all
over the sphere (proving a set stuck) is shown most blocks by a few such cones instead
of projecting the meshes along each direction."""


THIN_LAYER = 0.125
"""The share of the length tolerance below which a layer two parts share is not backed
out of (:meth:`Obstacles.backout`): settling it would move a part by about its
thickness, well within the length tolerance, and a shift that short is dropped."""


class Obstacles:
    """Convex bodies, hulls, solids, bounding spheres and pairwise cones, back-outs and
    blocking witnesses of one assembly's parts, each computed when first asked for and
    kept (one per assembly, in the :class:`~assemblykit.blocking.cache.BlockingCache` of
    its memo). The assembly is held weakly: the obstacles live in its memo, and refer
    back to it without keeping it alive."""

    def __init__(self, assembly: Assembly) -> None:
        self._owner = weakref.ref(assembly)
        self.pieces: dict[str, list[NDArray[np.float64]] | None] = {}
        self.cones: dict[tuple[str, str, Tolerance], list[NDArray[np.float64]]] = {}
        self.backouts: dict[tuple[str, str, Tolerance], NDArray[np.float64]] = {}
        self.hulls: dict[str, NDArray[np.float64]] = {}
        self.balls: dict[str, NDArray[np.float64]] = {}
        self.lattice: dict[str, NDArray[np.int64] | None] = {}
        self.witnesses: dict[tuple[str, str], tuple[tuple[int, int], ...]] = {}
        """Per pair (moving, blocker) found blocking by the projection test, the pairs
        of faces that showed it along the last :data:`WITNESSES_KEPT` directions where
        none known before did, the latest first
        (:func:`~assemblykit.geometry.occlusion.witnesses_hold`)."""
        names = list(assembly.names)
        self.names = names
        bounds = np.array([assembly.parts[n].mesh.bounds for n in names]).reshape(-1, 2, 3)
        self.centers = bounds.mean(axis=1)
        self.radii = np.linalg.norm(bounds[:, 1] - bounds[:, 0], axis=1) / 2

    @property
    def assembly(self) -> Assembly:
        """The assembly whose parts these are."""
        assembly = self._owner()
        assert assembly is not None, "the assembly of these obstacles is gone"
        return assembly

    def keep_witness(self, pair: tuple[str, str], faces: tuple[int, int]) -> None:
        """Keep ``faces`` first among the witnesses of ``pair`` (:attr:`witnesses`)."""
        kept = self.witnesses.get(pair, ())
        self.witnesses[pair] = (faces, *(w for w in kept if w != faces))[:WITNESSES_KEPT]

    def of(self, name: str) -> list[NDArray[np.float64]] | None:
        """The convex bodies of a part, ``None`` when one of them is not convex."""
        if name not in self.pieces:
            self.pieces[name] = convex_bodies(
                self.assembly.parts[name].mesh, self.assembly.tolerance()
            )
        return self.pieces[name]

    def cells(self, name: str) -> NDArray[np.int64] | None:
        """The unit cells a part is made of, ``None`` when it is not
        (:func:`~assemblykit.blocking.lattice.lattice_cells`), found once."""
        if name not in self.lattice:
            self.lattice[name] = lattice_cells(self.assembly.parts[name].mesh)
        return self.lattice[name]

    def convex(self, name: str) -> bool:
        """Whether the part is a union of convex bodies (cones are exact for it)."""
        return self.of(name) is not None

    def hull(self, name: str) -> NDArray[np.float64]:
        """The vertices of a part's convex hull (all its vertices where the hull is
        degenerate: a flat part), found once."""
        if name not in self.hulls:
            self.hulls[name] = hull_vertices(self.assembly.parts[name].mesh)
        return self.hulls[name]

    def spheres(self, name: str) -> NDArray[np.float64]:
        """Per triangle of a part's mesh, a ball holding it (centre, radius), found once
        (:func:`~assemblykit.geometry.occlusion.triangle_spheres`)."""
        if name not in self.balls:
            self.balls[name] = triangle_spheres(self.assembly.parts[name].mesh)
        return self.balls[name]

    def solid(self, name: str) -> manifold3d.Manifold:
        """The manifold3d solid of a part's mesh, made once for the assembly
        (:func:`~assemblykit.geometry.interference.part_solid`)."""
        return part_solid(self.assembly, name)

    def backout(self, moving: str, blocker: str, tol: ModelTolerance) -> NDArray[np.float64]:
        """The translation that backs ``moving`` out of ``blocker`` before blocking is
        decided: their separation when they share a volume counted as touching (module
        docstring), beyond rounding (the cube of the length tolerance), and it is longer
        than the length tolerance the tests allow anyway, else zero. A layer thinner than
        :data:`THIN_LAYER` of the length tolerance (:func:`layer_thickness`: the first
        step of settling) is not settled: settling moves a part by about that thickness,
        and such a shift is dropped (the layers a settled assembly keeps, 1e-6 thick on
        the ASAP beam whose length tolerance is 9e-5)."""
        key = (moving, blocker, tol)
        if key not in self.backouts:
            flipped = (blocker, moving, tol)
            if flipped in self.backouts:
                self.backouts[key] = -self.backouts[flipped]
            else:
                a, b = self.assembly.parts[moving].mesh, self.assembly.parts[blocker].mesh
                shift = np.zeros(3)
                # parts whose boxes are apart share no volume: no solid is made for them
                apart = np.any(a.bounds[0] > b.bounds[1]) or np.any(b.bounds[0] > a.bounds[1])
                volume, thickness = (
                    (0.0, 0.0)
                    if apart
                    else layer_thickness(self.solid(moving), self.solid(blocker))
                )
                # a volume below the cube of the length tolerance is rounding: no
                # layer to back out of (a pin trimmed to its hole, which would be
                # backed out along its whole length)
                if (
                    tol.length**3 < volume <= interference_threshold(a, b, tol)
                    and thickness > THIN_LAYER * tol.length
                ):
                    pair = [self.solid(moving), self.solid(blocker)]
                    shifts = settle([a, b], [(0, 1)], pair).shifts
                    if np.linalg.norm(shifts[0] - shifts[1]) > tol.length:
                        shift = shifts[0] - shifts[1]
                self.backouts[key] = shift
        return self.backouts[key]

    def cones_of(self, moving: str, blocker: str, tol: ModelTolerance) -> list[NDArray[np.float64]]:
        """The cones along which ``blocker`` blocks ``moving``, both unions of convex
        bodies (:meth:`convex`; other parts go to the projection test, which backs them
        out). An empty cone (they overlap) is recomputed with ``moving`` backed out of
        ``blocker`` (:meth:`backout`)."""
        key = (moving, blocker, tol)
        if key not in self.cones:
            flipped = (blocker, moving, tol)
            if flipped in self.cones:
                self.cones[key] = [-c for c in self.cones[flipped]]
            else:
                self.cones[key] = self._cones(moving, blocker, tol, np.zeros(3))
                if any(len(c) == 0 for c in self.cones[key]):
                    shift = self.backout(moving, blocker, tol)
                    if shift.any():
                        self.cones[key] = self._cones(moving, blocker, tol, shift)
        return self.cones[key]

    def _cones(
        self, moving: str, blocker: str, tol: ModelTolerance, shift: NDArray[np.float64]
    ) -> list[NDArray[np.float64]]:
        pieces, obstacles = self.of(moving), self.of(blocker)
        assert pieces is not None and obstacles is not None
        return [blocking_cone(q, p + shift, tol) for p, q in itertools.product(pieces, obstacles)]
