"""Interfering parts as a fitter reads them (docs/planning.md, "Interfering parts").

CAD models often draw parts overlapping on purpose: a self-tapping screw at its thread's
diameter in a smaller pilot hole, a press-fitted pin, meshing gear teeth, wood joints.
Taken literally, each such pair shares a volume and blocks itself in every direction
(:mod:`assemblykit.geometry.interference`), so nothing comes apart. A fitter reads them
otherwise, and :func:`resolve_overlaps` does the same, saying what it did for each pair:

* **joined** parts (``join``, and with ``join_interfering`` every connected set of
  interfering parts) become one rigid part named ``A+B``: the union of their solids
  (manifold3d). The solids of one product of several solids that touch one another (a
  locknut's nut and its nylon insert, captured in it) are one physical part, joined and
  named after the product, unless ``join_products`` is false; solids of a product apart
  from the others (a pattern of six bolts drawn as one body) stay parts of their own
  (:func:`touching_products`);
* **designed interference**: a pair sharing at most ``ignore_overlap`` (default:
  ``DESIGNED_SHARE`` of the smaller part's volume) has the shared volume cut from the
  smaller part, with all of that part in the shared volume's shadow along the axis it
  was pressed in by (:func:`insertion_axis`): the screw loses its thread's ring along its
  whole shank, the pin its press fit, so it touches the other and leaves the way it went
  in (unscrewing, for a screw: its helical motion follows the same axis);
* any other pair is left as it is, an obstacle in every direction, and named with its
  volume wherever it stops a plan; so is a pair of designed interference whose cut
  would leave the smaller part still sharing more than the interference threshold
  with the other.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import replace

import networkx as nx
import numpy as np
import trimesh
from numpy.typing import NDArray

from assemblykit.algebra import se3
from assemblykit.geometry.booleans import manifold3d
from assemblykit.geometry.interference import interference_threshold, interferences, solid
from assemblykit.geometry.occlusion import blocking_witnesses, shadows
from assemblykit.model.assembly import Assembly, Overlap, Part
from assemblykit.model.surfaces import Surface
from assemblykit.ragged import group_of, group_starts
from assemblykit.tolerance import ModelTolerance, Tolerance

DESIGNED_SHARE = 0.25
"""The largest shared volume, as a fraction of the smaller part's volume, read as
designed interference by default: a screw at its thread's diameter in a pilot hole 0.1
smaller (Ø3.0 in Ø2.9) shares about 7% of its shank, an M3 thread through a locknut's
nylon insert about 16% of the insert, a press fit well under 1%; parts sharing more are
taken as a modelling error and left as obstacles."""


def mesh_of(body: manifold3d.Manifold) -> trimesh.Trimesh:
    """The closed triangle mesh of a manifold3d solid."""
    return traced_mesh(body, -1)[0]


def traced_mesh(
    body: manifold3d.Manifold, original_id: int
) -> tuple[trimesh.Trimesh, NDArray[np.int64]]:
    """The closed triangle mesh of a manifold3d solid, and per triangle the face id of
    the face it lies on in the solid made with ``original_id``
    (:func:`~assemblykit.geometry.interference.solid`), or -1 where it comes from
    another solid. The mesh is taken as manifold3d gives it, its vertices already
    shared: merging the ones closer than trimesh's merge distance (a boolean leaves
    edges of 1e-10 where faces nearly meet) would open it."""
    mesh, originals, face_ids = _traced(body)
    return mesh, np.where((originals == original_id) & (original_id >= 0), face_ids, -1)


def _traced(
    body: manifold3d.Manifold,
) -> tuple[trimesh.Trimesh, NDArray[np.int64], NDArray[np.int64]]:
    """The closed triangle mesh of a manifold3d solid (:func:`traced_mesh`), and per
    triangle the original id of the solid it comes from and its face id there."""
    out = body.to_mesh64()
    faces = np.array(out.tri_verts, dtype=np.int64)
    vertices = np.array(out.vert_properties[:, :3], dtype=np.float64)
    mesh = trimesh.Trimesh(vertices, faces, process=False)
    bounds = np.asarray(out.run_index, dtype=np.int64) // 3
    runs = np.asarray(out.run_original_id, dtype=np.int64)
    originals = np.repeat(runs, np.diff(bounds))
    return mesh, originals, np.asarray(out.face_id, dtype=np.int64)


def joined(assembly: Assembly, groups: Iterable[Iterable[str]]) -> Assembly:
    """``assembly`` with each group of parts made one rigid part named by joining its
    members' names with ``+`` (in the assembly's order), its mesh the union of theirs;
    groups that share a part are one group. Where every member has exact surfaces, the
    joined part keeps them over the triangles of its mesh that lie on them (those inside
    the union are gone with their triangles: :func:`_joined_surfaces`)."""
    return _joined(assembly, groups)[0]


TOUCHING_GAP = 1e-3
"""The largest gap, a share of the smaller solid's bounding-box diagonal, between two
solids of one product that are read as touching (one physical part): a thousandth of
its size, beyond the sag of a tessellated curved face."""


def touching_products(assembly: Assembly) -> dict[str, tuple[str, ...]]:
    """The products of several solids (:attr:`~assemblykit.model.assembly.Assembly.products`)
    as the sets of their solids that touch or overlap one another, each within
    :data:`TOUCHING_GAP` of the next (manifold3d's ``min_gap``): a product whose solids
    all hang together keeps its name; each set of two solids or more of a product that
    falls apart is named by joining its solids' names with ``+``, and a solid touching
    no other of its product is no set (a part of its own)."""
    found: dict[str, tuple[str, ...]] = {}
    for product, members in assembly.products.items():
        meshes = {name: assembly[name].mesh for name in members}
        bodies = {name: solid(mesh, name) for name, mesh in meshes.items()}
        graph: nx.Graph = nx.Graph()
        graph.add_nodes_from(members)
        for a, b in itertools.combinations(members, 2):
            size = min(float(np.linalg.norm(np.ptp(meshes[n].bounds, axis=0))) for n in (a, b))
            gap = TOUCHING_GAP * size
            # min_gap answers its search length where nothing is nearer
            if bodies[a].min_gap(bodies[b], 2 * gap) <= gap:
                graph.add_edge(a, b)
        order = {name: k for k, name in enumerate(members)}
        sets = [
            tuple(sorted(c, key=order.__getitem__))
            for c in nx.connected_components(graph)
            if len(c) > 1
        ]
        if len(sets) == 1 and len(sets[0]) == len(members):
            found[product] = sets[0]
            continue
        found.update(("+".join(group), group) for group in sorted(sets, key=lambda g: order[g[0]]))
    return found


def join_products(assembly: Assembly) -> Assembly:
    """``assembly`` with the solids of each product of several solids
    (:attr:`~assemblykit.model.assembly.Assembly.products`: a locknut's nut and nylon
    insert, a hinge leaf drawn as a plate and its knuckles) made one rigid part named
    after the product, as :func:`resolve_overlaps` makes them, and nothing else done:
    ``joined`` lists each such part's solids, and the groups and supports name the
    parts they became."""
    if not assembly.products:
        return assembly
    result, into = _joined(assembly, (), touching_products(assembly))
    prepared = type(result).like(result, scale=result.scale)
    members: dict[str, list[str]] = {}
    for name, part in into.items():
        members.setdefault(part, []).append(name)
    prepared.joined = {part: tuple(names) for part, names in members.items()}
    prepared.products = {}
    prepared.groups = {
        group: tuple(dict.fromkeys(into.get(name, name) for name in names))
        for group, names in assembly.groups.items()
    }
    grounded = {into.get(name, name) for name in assembly.supports}
    prepared.supports = tuple(name for name in prepared.parts if name in grounded)
    return prepared


def _joined(
    assembly: Assembly,
    groups: Iterable[Iterable[str]],
    named: Mapping[str, Iterable[str]] | None = None,
) -> tuple[Assembly, dict[str, str]]:
    """:func:`joined`, and the name of the part each joined part became; a joined part
    whose members are exactly those of a ``named`` group takes that group's name."""
    graph: nx.Graph = nx.Graph()
    for group in [*groups, *(named or {}).values()]:
        names = [assembly.part(name).name for name in group]
        graph.add_nodes_from(names)
        graph.add_edges_from(itertools.pairwise(names))
    names_of = {frozenset(members): name for name, members in (named or {}).items()}
    order = {name: k for k, name in enumerate(assembly.parts)}
    result, into = assembly, {}
    for component in sorted(nx.connected_components(graph), key=lambda c: min(order[n] for n in c)):
        members = sorted(component, key=order.__getitem__)
        if len(members) < 2:
            continue
        parts = [assembly.parts[n] for n in members]
        mesh, member, face_ids = _union_mesh(parts, assembly.tolerance())
        surfaces = _joined_surfaces(parts, mesh, member, face_ids)
        name = names_of.get(frozenset(members), "+".join(members))
        part = Part(name, mesh, surfaces=surfaces, source=parts[0].source)
        rest = [n for n in result.parts if n not in component]
        result = result.subset(rest).with_part(part)
        into.update(dict.fromkeys(members, part.name))
    return result, into


def _union_mesh(
    parts: Sequence[Part], tol: ModelTolerance
) -> tuple[trimesh.Trimesh, NDArray[np.int64], NDArray[np.int64]]:
    """The closed mesh of the union of ``parts``, and per triangle the part it comes
    from (an index into ``parts``) and the number of the surface it lies on there
    (:func:`_numbered_solid`). Parts that share no volume beyond the interference
    threshold (the solids of one product, touching face to face) are their meshes side
    by side: the mesh of their boolean union keeps the faces where they touch as sheets
    of no thickness, and a solid made again from it is not their union (the 13 solids
    of a servo lost 4.5 mm³ and gained volume around a nut beside them). Parts that
    overlap are the mesh of their union (manifold3d)."""
    first_id = manifold3d.Manifold.reserve_ids(len(parts))
    solids = [_numbered_solid(part, first_id + k) for k, part in enumerate(parts)]
    union = manifold3d.Manifold.batch_boolean(solids, manifold3d.OpType.Add)
    shared = sum(piece.volume() for piece in solids) - union.volume()
    if shared > tol.length * min(float(part.mesh.area) for part in parts):
        mesh, originals, face_ids = _traced(union)
        return mesh, originals - first_id, face_ids
    starts = group_starts([len(part.mesh.vertices) for part in parts])
    faces = [part.mesh.faces + start for part, start in zip(parts, starts, strict=True)]
    vertices = np.concatenate([part.mesh.vertices for part in parts])
    mesh = trimesh.Trimesh(vertices, np.concatenate(faces), process=False)
    member = group_of([len(part.mesh.faces) for part in parts])
    face_ids = np.concatenate([_surface_numbers(part) for part in parts])
    return mesh, member, face_ids


def _surface_numbers(part: Part) -> NDArray[np.int64]:
    """Per triangle of ``part``, the number of the exact surface it lies on (its k-th
    surface k), the others each their own number after them."""
    ids = len(part.surfaces) + np.arange(len(part.mesh.faces))
    for k, surface in enumerate(part.surfaces):
        ids[surface.faces] = k
    return ids


def _numbered_solid(part: Part, original_id: int) -> manifold3d.Manifold:
    """The solid of ``part`` whose triangles carry, under ``original_id``, the number of
    the exact surface they lie on (its k-th surface k, the others each their own number
    after them: :func:`_surface_numbers`): a boolean's result then tells which surface
    each triangle lies on."""
    return solid(part.mesh, part.name, original_id=original_id, face_ids=_surface_numbers(part))


def _joined_surfaces(
    parts: Sequence[Part],
    mesh: trimesh.Trimesh,
    member: NDArray[np.int64],
    face_ids: NDArray[np.int64],
) -> tuple[Surface, ...]:
    """The exact surfaces of the union of ``parts`` whose mesh is ``mesh``, each of its
    triangles from part ``member`` (an index into ``parts``) on the surface numbered
    ``face_ids`` there (:func:`_numbered_solid`): each part's surfaces over the
    triangles left of them. None unless every part has exact surfaces (a part without
    them leaves the union's to recognition)."""
    if not all(part.surfaces for part in parts):
        return ()
    corners = np.asarray(mesh.triangles, dtype=np.float64)
    kept = []
    for m, part in enumerate(parts):
        for k, surface in enumerate(part.surfaces):
            faces = np.flatnonzero((member == m) & (face_ids == k))
            if len(faces):
                kept.append(surface.on_faces(faces, corners[faces]))
    return tuple(kept)


def insertion_axis(shared: trimesh.Trimesh) -> NDArray[np.float64]:
    """The axis along which a shared volume was pressed in: of its principal axes of
    inertia, the one along which its shadow is smallest (the ring a screw's thread shares
    with its hole casts the ring along the screw's axis, a pin's press fit likewise),
    the first of :func:`insertion_axes`."""
    return insertion_axes(shared)[0]


AXIS_SNAP_ANGLE = 0.01
"""Radians within which a principal axis of a shared volume is taken along the faces
of it that are nearly square to it (:func:`insertion_axes`): the axes of inertia of a
slab whose outline is not symmetric lean by a few thousandths of a radian, and a cut
along a leaning axis leaves the parts overlapping in a sliver all along it."""


def insertion_axes(shared: trimesh.Trimesh) -> list[NDArray[np.float64]]:
    """The principal axes of inertia of a shared volume, the one along which its shadow
    is smallest first, each taken along the area-weighted normal of its faces within
    :data:`AXIS_SNAP_ANGLE` of square to it, when it has such faces (a slab's faces, a
    ring's ends)."""
    axes = np.asarray(shared.principal_inertia_vectors, dtype=np.float64)
    normals, areas = np.asarray(shared.face_normals), np.asarray(shared.area_faces)
    shadows = [float(np.abs(normals @ axis) @ areas) / 2 for axis in axes]
    snapped = []
    for k in np.argsort(shadows, kind="stable").tolist():
        along = normals @ axes[k]
        square = np.abs(along) >= math.cos(AXIS_SNAP_ANGLE)
        mean = (normals[square] * (np.sign(along[square]) * areas[square])[:, None]).sum(axis=0)
        norm = float(np.linalg.norm(mean))
        snapped.append(mean / norm if norm > 0 else axes[k])
    return snapped


def _extruded_shadow(
    shared: trimesh.Trimesh, axis: NDArray[np.float64], length: float
) -> manifold3d.Manifold:
    """The prism of the shadow of ``shared`` along ``axis``, ``length`` long each way
    from the centre of ``shared``'s bounding box."""
    # the shadow's polygons, and so the prism's mesh, are drawn in this frame
    u, v = se3.axis_basis(axis, turned=True)
    flat = np.asarray(shared.vertices) @ np.column_stack([u, v])
    triangles = flat[np.asarray(shared.faces)]
    a, b = triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0]
    signed = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    triangles = np.where((signed < 0)[:, None, None], triangles[:, ::-1], triangles)
    shadow = manifold3d.CrossSection(
        [t for t, a in zip(triangles, np.abs(signed), strict=True) if a > 0],
        manifold3d.FillRule.Positive,
    )
    prism = manifold3d.Manifold.extrude(shadow, 2 * length)
    middle = float(np.mean(shared.bounds, axis=0) @ axis)
    frame = np.column_stack([u, v, axis, (middle - length) * axis])
    return prism.transform(frame)


def _trimmed(part: Part, other: Part, tol: ModelTolerance) -> Part | None:
    """``part`` without what it shares with ``other``, and without the rest of ``part``
    in that shared volume's shadow along the axis it was pressed in by: of its
    :func:`insertion_axes`, the first whose cut lets the two parts apart along it
    (:func:`_parts_leave_along`), else the first. A screw loses its thread's ring along
    the whole shank, so that it leaves along its axis through the hole it is screwed
    into; a plate that a motor is drawn through loses what the motor passes through,
    not a strip across it. Its exact surfaces keep the triangles that remain of them
    (:func:`_cut_surfaces`). A part that an earlier cut already took out of ``other``
    (a screw through two plates, trimmed along its whole shank by the first) is left
    as it is: what it still shares is rounding, whose shadow means nothing. ``None``
    when what the cut leaves of ``part`` still shares more than the interference
    threshold with ``other`` (a cut that cannot be made). The cut's mesh is measured
    again as it will be used: where reading it back collapses slivers into ``other``,
    ``other`` is subtracted from it once more (:func:`_cut_again`)."""
    # the triangles of surface k numbered k, the others each their own number after them
    count = len(part.surfaces)
    ids = count + np.arange(len(part.mesh.faces))
    for k, surface in enumerate(part.surfaces):
        ids[surface.faces] = k
    original_id = manifold3d.Manifold.reserve_ids(1)
    mine = solid(part.mesh, part.name, original_id=original_id, face_ids=ids)
    theirs = solid(other.mesh, other.name)
    common = mine ^ theirs
    if common.volume() <= interference_threshold(part.mesh, other.mesh, tol):
        return part
    bodies = _bodies(common)
    shared = mesh_of(bodies)
    size = float(np.linalg.norm(np.ptp(np.vstack([part.mesh.bounds, other.mesh.bounds]), axis=0)))
    # the first axis whose cut lets the two parts apart along it, else the first one
    first: tuple[manifold3d.Manifold, NDArray[np.float64]] | None = None
    for candidate in insertion_axes(shared):
        removed, axis = _removed_along(other, bodies, shared, candidate, size, tol)
        cut = _bodies(mine - removed)
        first = first or (cut, axis)
        if _parts_leave_along(mesh_of(cut), other.mesh, axis, tol):
            break
    else:
        assert first is not None  # a shared volume has three principal axes
        cut, axis = first
    mesh, source = traced_mesh(cut, original_id)
    if (cut ^ theirs).volume() > interference_threshold(mesh, other.mesh, tol):
        return None
    if (solid(mesh) ^ theirs).volume() > interference_threshold(mesh, other.mesh, tol):
        mesh, source = _cut_again(mesh, source, theirs)
        if (solid(mesh) ^ theirs).volume() > interference_threshold(mesh, other.mesh, tol):
            return None
    surfaces = _cut_surfaces(part, other, mesh, source, axis, tol) if part.surfaces else ()
    return replace(part, mesh=mesh, surfaces=surfaces)


def _removed_along(
    other: Part,
    bodies: manifold3d.Manifold,
    shared: trimesh.Trimesh,
    axis: NDArray[np.float64],
    size: float,
    tol: ModelTolerance,
) -> tuple[manifold3d.Manifold, NDArray[np.float64]]:
    """What :func:`_trimmed` cuts from a part that shares ``bodies`` (whose mesh is
    ``shared``) with ``other`` when it was pressed in along ``axis``, and the axis it
    then leaves along: the shadow of the shared volume along the axis, ``size`` long
    each way; in a hole of ``other`` (:func:`_hole_along`), along the hole's axis, with
    the thread's tube and the sheets where the part bears on the hole's face."""
    hole = _hole_along(other, shared, axis, tol)
    if hole is None:
        # a thread's ring with a sheet of the head where it bears on the hole's face:
        # the sheet's disc turns the principal axes, the hole's axis stays the same
        hole = _hole_along(other, shared, None, tol)
        axis = axis if hole is None or hole.axis is None else hole.axis
    sheets = None
    if hole is not None:
        bulk, sheets = _sheets(bodies, axis, hole.radius)
        if bulk is None:
            sheets = None
        else:
            shared = mesh_of(bulk)
    removed = _extruded_shadow(shared, axis, 2 * size)
    if hole is not None:
        removed = removed + _thread_tube(hole, shared, 2 * size)
    if sheets is not None:
        removed = removed + sheets
    return removed, axis


def _parts_leave_along(
    cut: trimesh.Trimesh, other: trimesh.Trimesh, axis: NDArray[np.float64], tol: ModelTolerance
) -> bool:
    """Whether a part trimmed to ``cut`` and ``other`` come apart along ``axis`` one way
    or the other (the projection test of :mod:`assemblykit.geometry.occlusion`): a cut
    along the axis a part was pressed in by lets it leave that way, unless the part that
    was pressed in is the larger one (a motor drawn through the plate that holds it:
    the plate's slab, cut along an axis in its plane, leaves the motor's body in the
    way)."""
    movers = np.array([[False, True], [False, False]])
    return any(
        not blocking_witnesses(shadows([cut, other], way * axis, tol), movers, tol, first_only=True)
        for way in (1.0, -1.0)
    )


def _cut_again(
    mesh: trimesh.Trimesh, source: NDArray[np.int64], theirs: manifold3d.Manifold
) -> tuple[trimesh.Trimesh, NDArray[np.int64]]:
    """The cut part's ``mesh`` (its triangles on the surfaces numbered ``source``, -1 on
    the cut) less ``theirs``, and the numbers of its triangles: a cut whose faces lie on
    the other part's leaves slivers thinner than manifold3d's tolerance, which its
    mesh, read back, collapses into the other part; subtracting the other part from
    that mesh removes what they then share."""
    cut_id = int(source.max(initial=0)) + 1
    original_id = manifold3d.Manifold.reserve_ids(1)
    again = solid(mesh, original_id=original_id, face_ids=np.where(source >= 0, source, cut_id))
    trimmed, numbers = traced_mesh(_bodies(again - theirs), original_id)
    return trimmed, np.where(numbers == cut_id, -1, numbers)


THREAD_CLEARANCE_SHARE = 0.01
"""How far inside a threaded hole's exact cylinder, as a share of its radius, a screw
trimmed in it is cut along its whole shank (:func:`_thread_tube`): every tessellation
of the hole (its chords lie within the angular deflection of the cylinder, 0.5% of the
radius at 0.2 rad, io/step.py) then lies outside the shank, so that holes of one
radius in several plates, faceted each at its own angles, all let it through."""

SEGMENTS = 256
"""Sides of the polygons that stand for exact circles in :func:`_thread_tube` (their
chords within 0.01% of the radius)."""


SHEET_SHARE = 0.01
"""The largest extent along a hole's axis, as a share of the hole's radius, of a piece
of the volume a part shares with it that is a sheet where a face of the part bears on
a face of the hole's part (a screw's head drawn a hair into the plate it stands on),
not a thread's or a press fit's ring: the sheet is cut from the part as it is, and
casts no shadow along the axis (:func:`_trimmed`)."""


def _sheets(
    shared: manifold3d.Manifold, axis: NDArray[np.float64], radius: float
) -> tuple[manifold3d.Manifold | None, manifold3d.Manifold | None]:
    """The pieces of ``shared`` thicker along ``axis`` than :data:`SHEET_SHARE` of
    ``radius``, and the thinner ones (the sheets), each joined (``None`` for none)."""
    thick: list[manifold3d.Manifold] = []
    thin: list[manifold3d.Manifold] = []
    for piece in shared.decompose():
        corners = np.asarray(piece.to_mesh().vert_properties, dtype=np.float64)[:, :3]
        flat = float(np.ptp(corners @ axis)) < SHEET_SHARE * radius
        (thin if flat else thick).append(piece)

    def joined(pieces: list[manifold3d.Manifold]) -> manifold3d.Manifold | None:
        return manifold3d.Manifold.batch_boolean(pieces, manifold3d.OpType.Add) if pieces else None

    return joined(thick), joined(thin)


def _hole_along(
    other: Part, shared: trimesh.Trimesh, axis: NDArray[np.float64] | None, tol: ModelTolerance
) -> Surface | None:
    """The hole (a cylinder of ``other`` with its material outside) along ``axis`` (any
    axis when ``None``) that the volume ``shared`` with it surrounds, its inner side on
    the cylinder and its centre of mass on the axis (within ``CUT_RADIUS_SHARE`` of the
    radius): a thread's ring in its pilot hole (``None`` when there is none)."""
    for surface in other.surfaces:
        if surface.kind != "cylinder" or surface.convex or surface.axis is None:
            continue
        if axis is not None and abs(float(surface.axis @ axis)) < 1.0 - tol.mesh_angle:
            continue
        points = np.vstack([np.asarray(shared.vertices), shared.center_mass])
        offset = points - surface.point
        across = np.linalg.norm(offset - np.outer(offset @ surface.axis, surface.axis), axis=1)
        near = CUT_RADIUS_SHARE * surface.radius
        if abs(float(across[:-1].min()) - surface.radius) <= near and across[-1] <= near:
            return surface
    return None


def ring_radius(volume: float, inner: float, length: float) -> float:
    """The outer radius of the ring of ``volume`` about a cylinder of radius ``inner``
    along ``length`` of it: the radius a thread's crests reach, read from the volume a
    screw shares with its hole."""
    return math.sqrt(volume / (math.pi * length) + inner**2)


def _thread_tube(hole: Surface, shared: trimesh.Trimesh, length: float) -> manifold3d.Manifold:
    """The tube about ``hole``'s axis from ``THREAD_CLEARANCE_SHARE`` inside its exact
    radius out to as far outside the outer radius of the ring of the volume and height
    of ``shared`` (faces that only touch leave sheets of no volume in a boolean, so
    the volume measures it, not the vertices), ``length`` long each way: cut from a
    screw trimmed in that hole, it leaves the shank inside every faceting of the hole
    and of holes of the same radius on the axis, so that it leaves along it through
    them all (the cut of the shared volume's shadow alone follows this hole's facets)."""
    assert hole.axis is not None
    axis = hole.axis
    along = (np.asarray(shared.vertices) - hole.point) @ axis
    height = max(float(np.ptp(along)), 1e-12)
    ring = ring_radius(abs(float(shared.volume)), hole.radius, height)
    outer = ring * (1.0 + THREAD_CLEARANCE_SHARE)
    inner = hole.radius * (1.0 - THREAD_CLEARANCE_SHARE)
    ring = manifold3d.CrossSection.circle(outer, SEGMENTS) - manifold3d.CrossSection.circle(
        inner, SEGMENTS
    )
    # the circles' first vertices lie along u: the tube's facets turn with the frame
    u, v = se3.axis_basis(axis, turned=True)
    start = hole.point - length * axis
    return manifold3d.Manifold.extrude(ring, 2 * length).transform(
        np.column_stack([u, v, axis, start])
    )


CUT_RADIUS_SHARE = 0.05
"""How far, as a share of its radius, the cut a part's trimming leaves may lie from a
cylinder of the other part and still be taken as lying on it (:func:`_cut_surfaces`):
the cut runs along the other part's tessellated hole, whose facets lie within the
tessellation's deflection of the exact cylinder (io/step.py)."""


def _cut_surfaces(
    part: Part,
    other: Part,
    mesh: trimesh.Trimesh,
    source: NDArray[np.int64],
    axis: NDArray[np.float64],
    tol: ModelTolerance,
) -> tuple[Surface, ...]:
    """The exact surfaces of ``part`` trimmed by ``other`` to ``mesh``, whose triangles
    lie on the surfaces of ``part`` numbered ``source`` (its k-th surface k, -1 on the
    cut, others beyond the surfaces' count): each surface of
    ``part`` over the triangles left of it, and the cut, where it lies on a cylinder of
    ``other`` along ``axis`` (within ``CUT_RADIUS_SHARE`` of its radius), as that
    cylinder seen from ``part``'s side (a pilot hole becomes the trimmed screw's shank)."""
    corners = np.asarray(mesh.triangles, dtype=np.float64)
    kept = []
    for k, surface in enumerate(part.surfaces):
        faces = np.flatnonzero(source == k)
        if len(faces):
            kept.append(surface.on_faces(faces, corners[faces]))
    cut = np.flatnonzero(source < 0)
    for surface in other.surfaces:
        if not len(cut) or surface.kind != "cylinder" or surface.axis is None:
            continue
        if abs(float(surface.axis @ axis)) < 1.0 - tol.mesh_angle:
            continue
        offset = corners[cut].reshape(-1, 3) - surface.point
        across = np.linalg.norm(offset - np.outer(offset @ surface.axis, surface.axis), axis=1)
        near = np.abs(across - surface.radius) <= max(tol.length, CUT_RADIUS_SHARE * surface.radius)
        on = near.reshape(-1, 3).all(axis=1)
        if on.any():
            faces = cut[on]
            flipped = replace(surface, convex=not surface.convex)
            kept.append(flipped.on_faces(faces, corners[faces]))
            cut = cut[~on]
    return tuple(kept)


def _bodies(body: manifold3d.Manifold) -> manifold3d.Manifold:
    """``body`` without the sheets of no volume a boolean leaves where faces only touch
    (pieces under ``1e-6`` of its volume)."""
    pieces = [piece for piece in body.decompose() if piece.volume() > 1e-6 * body.volume()]
    return manifold3d.Manifold.batch_boolean(pieces, manifold3d.OpType.Add)


def resolve_overlaps(
    assembly: Assembly,
    join: Sequence[Sequence[str]] = (),
    join_interfering: bool = False,
    ignore_overlap: float | None = None,
    tol: Tolerance | None = None,
    *,
    join_products: bool = True,
) -> Assembly:
    """``assembly`` with its interfering parts resolved as the module docstring says,
    and :attr:`~assemblykit.model.assembly.Assembly.overlaps` listing every interfering
    pair with its volume and resolution (``joined``: the parts each joined part is made
    of). ``ignore_overlap`` is a volume in cubed model
    units (``0``: cut nothing; ``None``: ``DESIGNED_SHARE`` of the smaller part's
    volume). With ``join_products``, the solids of each product of several solids
    (:attr:`~assemblykit.model.assembly.Assembly.products`: a locknut's nut and nylon
    insert) are one part named after the product. A joined part is measured again
    against the other parts, so a screw through a locknut meets nut and insert as one
    part, and its designed interference with them is cut as any other."""
    tol = assembly.tolerance(tol)
    found = interferences(assembly, tol)
    groups = [list(group) for group in join]
    if join_interfering:
        groups += [[a, b] for a, b, _ in found]
    result, into = _joined(assembly, groups, touching_products(assembly) if join_products else None)
    overlaps = [
        Overlap(a, b, volume, "joined")
        for a, b, volume in found
        if a in into and into[a] == into.get(b)
    ]
    pending = [(a, b, volume) for a, b, volume in found if a not in into and b not in into]
    if into:
        order = {name: k for k, name in enumerate(result.parts)}
        pending = sorted(
            {*pending, *interferences(result, tol, among=set(into.values()))},
            key=lambda pair: (order[pair[0]], order[pair[1]]),
        )
    whole = dict(result.parts)
    for a, b, volume in pending:
        small, large = sorted((whole[a], whole[b]), key=lambda p: p.volume)
        limit = DESIGNED_SHARE * small.volume if ignore_overlap is None else ignore_overlap
        trimmed = None if volume > limit else _trimmed(result.parts[small.name], large, tol)
        if trimmed is None:
            overlaps.append(Overlap(a, b, volume))
            continue
        result = result.with_part(trimmed)
        overlaps.append(Overlap(a, b, volume, f"trimmed from {small.name}"))
    prepared = type(result).like(result, scale=result.scale)
    prepared.overlaps = tuple(replace(o, units=assembly.units) for o in overlaps)
    members: dict[str, list[str]] = {}
    for name, part in into.items():
        members.setdefault(part, []).append(name)
    prepared.joined = {part: tuple(names) for part, names in members.items()}
    # a part joined to a support stands on the ground as the support did
    grounded = {into.get(name, name) for name in assembly.supports}
    prepared.supports = tuple(name for name in prepared.parts if name in grounded)
    return prepared
