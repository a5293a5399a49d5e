"""Contacts between the parts of an assembly: how they are found, and kept with it.

The functions below find them (:func:`find_contacts`): after the broad phase
(:mod:`~assemblykit.geometry.broad_phase`: the pairs of parts whose bounding boxes meet,
inflated by the length tolerance), the narrow phase
(:mod:`~assemblykit.geometry.narrow_phase`), vectorised over all candidate pairs at
once, makes the planar patches where coplanar groups of facets of the two parts lie in
one plane with opposite normals, and the curved patches where coaxial cylinders and
cones or concentric spheres of equal size coincide. The curved surfaces are read from
the parts' exact surfaces, or recognised on each part's triangles within reach of the
other's box (:func:`near_curved_surfaces`: per pair, so a pair's contacts depend on its
two parts alone). A coplanar group with a face on such a surface is a facet of it, not
a planar face, and makes no planar patch. Last, the directions of the patches found are
snapped (:mod:`~assemblykit.geometry.snapping`): noisy normals of one direction become
one direction.

What is found is kept with the assembly: :func:`assembly_contacts` (contacts per
tolerance) and :func:`assembly_surfaces` (surfaces per part and tolerance) fill a
:class:`GeometryMemo`, the store of this kind in the assembly's
:class:`~assemblykit.model.assembly.Memo` (:func:`memo_of`), not a module global keyed by
assembly. The model owns the memo and knows only the protocol of its stores
(``model.assembly.Store``); this layer defines and fills the store. So it lives and dies
with the assembly, two assemblies never share one, and a sub-assembly keeps what
concerns its own parts (:meth:`GeometryMemo.restricted`, through ``Assembly.subset``
and ``with_part``): taking parts away costs nothing, and adding one costs only that
part's contacts.

The contacts found are the values of :mod:`~assemblykit.geometry.contact_values`
(:class:`Contact`, :class:`Contacts`, :class:`PlanarPatch`, :class:`CurvedPatch`). This
module names them too, with the public functions and constants of the broad phase, the
narrow phase and snapping (``__all__``), so that each can be imported from here.
"""

from __future__ import annotations

from collections.abc import Set
from dataclasses import dataclass, field
from functools import singledispatch

import numpy as np
from numpy.typing import NDArray

from assemblykit.deprecation import moved
from assemblykit.geometry.broad_phase import (
    PartStack,
    boxes_overlap,
    candidate_pairs,
    facing_groups,
    stack_parts,
)
from assemblykit.geometry.contact_values import (
    Contact,
    Contacts,
    CurvedKind,
    CurvedPatch,
    PlanarPatch,
)
from assemblykit.geometry.narrow_phase import (
    OUTLINE_PAIRS,
    OVERLAP_CHUNK,
    curved_contact,
    direction_reach,
    group_deviation,
    group_overlaps,
    may_fit,
    planar_matches,
    planar_patches,
    surface_size,
)
from assemblykit.geometry.polygons import polygon_contacts
from assemblykit.geometry.recognition import recognise_curved, recognise_planes, segment
from assemblykit.geometry.snapping import snap_classes, snapped
from assemblykit.model.assembly import Assembly
from assemblykit.model.polygons import PolygonAssembly
from assemblykit.model.surfaces import Surface
from assemblykit.tolerance import Tolerance

__all__ = [
    "OUTLINE_PAIRS",
    "OVERLAP_CHUNK",
    "WHOLE_SHARE",
    "Contact",
    "Contacts",
    "CurvedKind",
    "CurvedPatch",
    "GeometryMemo",
    "PartStack",
    "PlanarPatch",
    "assembly_contacts",
    "assembly_curved_surfaces",
    "assembly_surfaces",
    "candidate_pairs",
    "curved_contact",
    "direction_reach",
    "facing_groups",
    "find_contacts",
    "group_deviation",
    "group_overlaps",
    "memo_of",
    "near_curved_surfaces",
    "snap_classes",
    "snapped",
    "stack_parts",
    "surface_size",
]


def _surface_triangles(assembly: Assembly, name: str, surface: Surface) -> NDArray[np.float64]:
    mesh = assembly.parts[name].mesh
    faces = np.asarray(mesh.faces, dtype=np.int64)[surface.faces]
    return np.asarray(mesh.vertices, dtype=np.float64)[faces]


def _sorted_member(values: NDArray[np.int64], keys: NDArray[np.int64]) -> NDArray[np.bool_]:
    """Whether each of ``values`` is among the sorted, distinct, non-empty ``keys``
    (``np.isin``, by binary search: the keys are many and already sorted)."""
    at = np.minimum(np.searchsorted(keys, values), len(keys) - 1)
    found: NDArray[np.bool_] = keys[at] == values
    return found


def find_contacts(
    assembly: Assembly, tol: Tolerance | None = None, *, only: str | None = None
) -> list[Contact]:
    """The contacts between the touching parts of ``assembly``, in part order (module
    docstring); with ``only``, just the contacts of that part. ``tol`` is a policy that
    :meth:`Assembly.tolerance` scales to the model. Directions are snapped
    (:func:`~assemblykit.geometry.snapping.snapped`) within the policy alone: a measured
    joint mismatch says where faces may meet, not that their directions are one."""
    policy = assembly.policy_tolerance(tol)
    tol = assembly.tolerance(tol)
    names = list(assembly.parts)
    if len(names) < 2:
        return []
    stack = stack_parts(p.mesh for p in assembly)
    seg = segment(stack.vertices, stack.faces, tol)
    part_lo = np.array([p.mesh.bounds[0] for p in assembly.parts.values()])
    part_hi = np.array([p.mesh.bounds[1] for p in assembly.parts.values()])
    pairs = candidate_pairs(
        np.stack([part_lo, part_hi], axis=1),
        tol.length,
        None if only is None else names.index(only),
    )
    curved_part = np.zeros(len(names), dtype=bool)
    curved_part[stack.part[np.isin(seg.region, np.flatnonzero(seg.curved))]] = True
    # per ordered pair (k, other): the curved surfaces of part k where it may touch other
    surfaces: dict[tuple[int, int], tuple[Surface, ...]] = {}
    for a, b in pairs.tolist():
        for k, other in ((a, b), (b, a)):
            if assembly.parts[names[k]].surfaces or curved_part[k]:
                surfaces[k, other] = near_curved_surfaces(assembly, names[k], names[other], tol)

    group_part = stack.part[seg.order[seg.start[:-1]]]
    g, h = planar_matches(stack, seg, group_part, seg.flat, part_lo, part_hi, pairs, tol)
    # a coplanar group with a face on a curved surface of its part (where that part may
    # touch the other) is a facet of that surface, not a planar face
    groups_on: dict[Surface, NDArray[np.int64]] = {}
    for (k, _), near in surfaces.items():
        for s in near:
            if s not in groups_on:
                groups_on[s] = np.unique(seg.group[stack.face_start[k] + s.faces])
    on_curved = [
        (k * len(names) + other) * len(seg.flat) + groups_on[s]
        for (k, other), near in surfaces.items()
        for s in near
    ]
    if on_curved:
        keys = np.unique(np.concatenate(on_curved))
        pg, ph = group_part[g], group_part[h]
        facet = _sorted_member((pg * len(names) + ph) * len(seg.flat) + g, keys) | _sorted_member(
            (ph * len(names) + pg) * len(seg.flat) + h, keys
        )
        g, h = g[~facet], h[~facet]
    k, patches = planar_patches(stack, seg, g, h, tol)
    planar: dict[tuple[int, int], list[PlanarPatch]] = {}
    for m, flat in zip(k, patches, strict=True):
        planar.setdefault((int(group_part[g[m]]), int(group_part[h[m]])), []).append(flat)

    triangles: dict[tuple[int, int, int], NDArray[np.float64]] = {}

    def triangles_of(k: int, other: int, index: int) -> NDArray[np.float64]:
        if (k, other, index) not in triangles:
            triangles[k, other, index] = _surface_triangles(
                assembly, names[k], surfaces[k, other][index]
            )
        return triangles[k, other, index]

    curved: dict[tuple[int, int], list[CurvedPatch]] = {}
    for a, b in pairs.tolist():
        first, second = surfaces.get((a, b), ()), surfaces.get((b, a), ())
        for i, j in may_fit(first, second, tol):
            both = (triangles_of(a, b, i), triangles_of(b, a, j))
            patch = curved_contact(first[i], second[j], (names[a], names[b]), both, tol)
            if patch is not None:
                curved.setdefault((a, b), []).append(patch)

    found = [
        Contact(names[a], names[b], tuple(planar.get(key, ())), tuple(curved.get(key, ())))
        for key in sorted(set(planar) | set(curved))
        for a, b in [key]
        if planar.get(key) or curved.get(key)
    ]
    return snapped(found, policy)


@dataclass(eq=False)
class GeometryMemo:
    """What the geometry of an assembly's parts gave, a store of its memo (module
    docstring): ``contacts`` per tolerance, with the names of the parts they cover,
    ``surfaces`` per part name and tolerance, the ``curved`` ones among them (recognised
    first, without the planes), and the curved surfaces ``near`` per part, other part
    and tolerance (those contacts ask for: :func:`near_curved_surfaces`)."""

    contacts: dict[Tolerance, tuple[frozenset[str], Contacts]] = field(default_factory=dict)
    surfaces: dict[tuple[str, Tolerance], tuple[Surface, ...]] = field(default_factory=dict)
    curved: dict[tuple[str, Tolerance], tuple[Surface, ...]] = field(default_factory=dict)
    near: dict[tuple[str, str, Tolerance], tuple[Surface, ...]] = field(default_factory=dict)

    def restricted(self, names: Set[str]) -> GeometryMemo:
        """What still holds for the parts ``names`` alone: the contacts among them and
        their surfaces."""
        return GeometryMemo(
            {
                key: (covered & names, Contacts(c for c in found if c.a in names and c.b in names))
                for key, (covered, found) in self.contacts.items()
            },
            {key: found for key, found in self.surfaces.items() if key[0] in names},
            {key: found for key, found in self.curved.items() if key[0] in names},
            {key: found for key, found in self.near.items() if {key[0], key[1]} <= names},
        )


def memo_of(assembly: Assembly) -> GeometryMemo:
    """The :class:`GeometryMemo` of ``assembly`` (in its memo), an empty one on first use."""
    return assembly.memo.of(GeometryMemo)


def assembly_surfaces(
    assembly: Assembly, name: str, tol: Tolerance | None = None
) -> tuple[Surface, ...]:
    """The surfaces of part ``name``: its exact CAD surfaces, else those recognised on
    its mesh (:func:`~assemblykit.geometry.recognition.recognise`: the curved ones of
    :func:`assembly_curved_surfaces`, then the planes), once per tolerance."""
    part = assembly.part(name)
    if part.surfaces:
        return part.surfaces
    key = (name, assembly.tolerance(tol))
    memo = memo_of(assembly).surfaces
    if key not in memo:
        curved = assembly_curved_surfaces(assembly, name, tol)
        memo[key] = curved + recognise_planes(part.mesh, curved, key[1])
    return memo[key]


def assembly_curved_surfaces(
    assembly: Assembly, name: str, tol: Tolerance | None = None
) -> tuple[Surface, ...]:
    """The surfaces of part ``name`` other than planes: of its exact CAD surfaces, else
    those recognised on its mesh
    (:func:`~assemblykit.geometry.recognition.recognise_curved`), once per tolerance."""
    part = assembly.part(name)
    if part.surfaces:
        return tuple(s for s in part.surfaces if s.kind != "plane")
    key = (name, assembly.tolerance(tol))
    memo = memo_of(assembly).curved
    if key not in memo:
        memo[key] = recognise_curved(part.mesh, key[1])
    return memo[key]


WHOLE_SHARE = 0.25
"""The share of a part's triangles within reach of another part beyond which the curved
surfaces of the whole part serve that pair (:func:`near_curved_surfaces`): recognised
once, and kept for all its pairs and its features, they cost less than regions that
large recognised again pair by pair (a housing touching a dozen parts)."""


def near_curved_surfaces(
    assembly: Assembly, name: str, other: str, tol: Tolerance | None = None
) -> tuple[Surface, ...]:
    """The curved surfaces of part ``name`` where it may touch part ``other``: all of its
    exact CAD surfaces other than planes, else those recognised
    (:func:`~assemblykit.geometry.recognition.recognise_curved`) on its triangles whose
    bounding boxes meet ``other``'s, inflated by the length tolerance (every triangle
    within the tolerance of ``other`` is among them), once per pair and tolerance; when
    these are more than :data:`WHOLE_SHARE` of its triangles, those of the whole part
    (:func:`assembly_curved_surfaces`, kept for every pair and for its features).

    So a pair's contacts depend on its two parts alone, and recognition costs what the
    region where they meet holds rather than the whole part: on the ASAP beam, a
    beam's end on its post is 24% of its triangles, a post's top on the beam 6%."""
    part = assembly.part(name)
    if part.surfaces:
        return assembly_curved_surfaces(assembly, name, tol)
    key = (name, other, assembly.tolerance(tol))
    memo = memo_of(assembly).near
    if key not in memo:
        lo, hi = assembly.part(other).mesh.bounds
        first, second, third = np.asarray(part.mesh.triangles, dtype=np.float64).transpose(1, 0, 2)
        low = np.minimum(np.minimum(first, second), third)
        high = np.maximum(np.maximum(first, second), third)
        reach = np.flatnonzero(boxes_overlap(low, high, lo, hi, key[2].length))
        memo[key] = (
            assembly_curved_surfaces(assembly, name, tol)
            if len(reach) > WHOLE_SHARE * len(first)
            else recognise_curved(part.mesh, key[2], reach)
        )
    return memo[key]


@singledispatch
def assembly_contacts(assembly: object, tol: Tolerance | None = None) -> list[Contact]:
    """The contacts between the touching parts of ``assembly``, dispatched on its type:
    an :class:`~assemblykit.model.assembly.Assembly` (:func:`_mesh_contacts`) or a
    :class:`~assemblykit.model.polygons.PolygonAssembly` (its contact segments,
    :func:`~assemblykit.geometry.polygons.polygon_contacts`)."""
    raise TypeError(f"no contacts for a {type(assembly).__name__}")


assembly_contacts.register(PolygonAssembly, polygon_contacts)


@assembly_contacts.register
def _mesh_contacts(assembly: Assembly, tol: Tolerance | None = None) -> Contacts:
    """The contacts between touching parts, computed once per tolerance
    (:func:`find_contacts`); for parts the memo does not cover yet (one added by
    ``Assembly.with_part``) only their own contacts are found and added."""
    key = assembly.tolerance(tol)
    memo = memo_of(assembly).contacts
    covered, found = memo.get(key, (frozenset(), Contacts()))
    missing = [name for name in assembly.parts if name not in covered]
    if missing:
        if not covered:
            found = Contacts(find_contacts(assembly, tol))
        else:
            found, added = Contacts(found), set[str]()
            for name in missing:
                found += [
                    c
                    for c in find_contacts(assembly, key, only=name)
                    if c.a not in added and c.b not in added
                ]
                added.add(name)
        memo[key] = (frozenset(assembly.parts), found)
    return found


__getattr__ = moved(__name__, {"triangle_overlaps": "assemblykit.geometry.contacts:group_overlaps"})
