"""Tessellations that lie inside their exact solids (docs/geometry.md, "STEP tessellation").

A CAD kernel tessellates a curved face with its vertices *on* the exact surface, so each
triangle's chord sags off the surface by up to the linear deflection. On a convex
surface (a shaft, a ball, a male cone) the sag goes into the material and the mesh lies
inside the solid. On a concave one (a hole, a female cone, a socket) it goes into the
void: a plate's mesh bulges into its hole, and a pin modelled at exactly the hole's
diameter, whose mesh reaches the same circle from inside, shares a volume with it
although the exact solids share none.

:func:`inside_vertices` moves the vertices of every surface whose chords leave the
material just far enough into the material that each of its triangles lies on the
material side of the exact surface. The rule is a half-space that touches the surface:

* **cylinder** of radius ``r`` (a hole). Seen along the axis, a triangle's vertices lie
  in the directions ``u_i`` from the axis; let ``w`` be the middle of the narrowest arc
  that holds them. The half-plane ``x . w >= r`` touches the circle and holds no point
  of the hole, and it holds a vertex at radius ``q r`` iff ``q >= 1 / (u_i . w)``. Each
  vertex goes out along its own direction ``u_i`` (so no direction changes) to the
  largest radius its triangles ask for, and every triangle lies in its half-plane. A
  regular ``n``-gon inscribed in the circle becomes the circumscribed one: its vertices
  go to ``r / cos(pi / n)`` and its chords touch the circle.
* **cone** (a female cone, apex ``c``, half-angle ``alpha``): the central projection
  from the apex onto the plane one unit along the axis maps the cone onto a circle of
  radius ``tan(alpha)`` and triangles onto triangles, so the cylinder's rule holds with
  ``rho / s`` for the radius (``s`` the distance along the axis). Vertices move across
  the axis at constant ``s``.
* **sphere** (a socket): the same half-space in three dimensions, ``w`` the centre of
  the smallest cap of directions holding the triangle's vertices (its circumcentre, or
  the middle of its longest side).
* **torus** (major radius ``R``, tube radius ``t``), male or female (the material inside
  or outside the tube, read from the triangles' outward normals): a triangle's points,
  drawn in the half-plane ``(rho, z)`` of the axis, lie within ``delta = rho_max (1 -
  cos(phi / 2))`` (towards the axis) of the convex combinations of its vertices, ``phi``
  the arc of azimuth it spans. Where the material is outside the tube, the vertices go
  out from the tube's centre to the half-plane that lies ``delta`` beyond the tube (the
  cylinder's rule in the half-plane, ``delta`` counted only where the shift goes towards
  the tube); where it is inside, the vertices of triangles that reach the inner side of
  the tube (a hole's rounded rim) go in to ``t - delta`` from the tube's centre.

Every move is found in closed form (along a line where the constraint is linear or the
norm convex); the few that are not, and those that change a vertex's direction (a
socket's rim, below), are refined by repeating the whole rule, ``MAX_ROUNDS`` times at
most, until no vertex moves by more than float rounding. Surfaces whose chords lie in
the material (convex cylinders, cones and spheres, planes), spindle tori (whose tube
crosses the axis) and faces of other types are left alone.

**Neighbouring faces.** A vertex on the rim of a curved face is shared with the faces
around it. When it lies on planes (of the same part) its move stays in them, so planar
faces stay planar and planar contacts are unchanged. About an axis the move also keeps
the vertex's direction across the axis (the azimuths that cylindrical and conical
contacts read): in one plane it is the line the plane cuts from the half-plane through
the axis (a hole through a face perpendicular to its axis moves radially in the face;
one through a slanted face slides along the face), on two planes the line where they
meet if it lies in that half-plane. A socket's rim slides in its plane away from the
rim's centre, which turns its direction from the sphere's centre by about the move over
the radius (no other move can take the rim's chords out of the ball). A vertex on three
planes, on two whose line leaves the half-plane, or whose move in its planes would go
along the surface rather than into the material (a plane tangent to the surface: a
slot's sides, the faces a fillet joins), does not move at all. Such a *pinned* vertex
stays on the exact surface, and the half-space of each triangle that holds one touches
the surface there (``w = u`` of the pinned vertex), so its other vertices go further, by
up to about four times the sag. Only an edge between two pinned vertices of different
directions keeps its sag (where a male torus meets its tangent plane that sag is of the
second order). A vertex shared with a convex curved face, or a face of another type,
moves as the concave surface asks, taking that face's triangles along by at most the
sag. A vertex of several concave surfaces takes the largest of their moves, and the
next round moves it again if the others still ask for it (two crossing holes; coaxial
faces, a hole and its countersink, agree at once).

The mesh keeps its triangles and its orientation; vertices move by at most about the
sag of their triangles, i.e. the linear deflection of the tessellation, so the mesh lies
inside the solid and within the linear deflection of it (within about four times it next
to pinned vertices).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from assemblykit.model.surfaces import Surface

#: The least cosine between a vertex's move in its planes and the surface's normal; a
#: move closer to the surface than this pins the vertex (module docstring).
MIN_COS = 0.1
#: A triangle that spans an arc whose half-angle has a cosine under this asks no move
#: (no tessellation of a solid has one).
MIN_DOT = 0.1
#: Rounds of the rule at most (module docstring).
MAX_ROUNDS = 8
#: Moves after the first round below this fraction of the model's size are float
#: rounding, and lengths below it of a surface's size are points on its axis.
ROUNDING = 1e-12
#: Two planes whose unit normals' cross product is shorter than this are one plane.
PARALLEL = 1e-9

_PAIRS = ((0, 1), (1, 2), (0, 2))

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]


def sags_out(surface: Surface) -> bool:
    """Whether the chords of ``surface``'s triangles may leave the material: a concave
    cylinder, cone or sphere, and a ring torus (the inner side of a male torus is concave
    about its axis). A spindle torus (its tube as wide as its major radius or wider, so
    that the tube crosses the axis: a lemon or an apple shape, the fit CAD exporters give
    a large arc turned about an axis) is left alone: the rule reads each vertex from the
    tube's centre at its own azimuth, which is not the nearest one there."""
    if surface.kind == "torus":
        return surface.minor_radius < surface.radius
    return surface.kind in ("cylinder", "cone", "sphere") and not surface.convex


def inside_vertices(
    vertices: FloatArray, faces: IntArray, surfaces: Sequence[Surface]
) -> FloatArray:
    """The vertices of the closed mesh ``(vertices, faces)`` moved into the material so
    that the triangles of each of its ``surfaces`` (exact surfaces, their ``faces``
    numbering triangles of ``faces``) lie on the material side of that surface (module
    docstring): a mesh whose vertices lie on its exact solid's surface then lies inside
    the solid, within the linear deflection of it. Returns a new float64 array; the
    faces, and with them the mesh's orientation, stay as they are."""
    moved = np.array(vertices, dtype=np.float64)
    triangles = np.asarray(faces, dtype=np.int64)
    sagging = [s for s in surfaces if sags_out(s) and len(s.faces)]
    if not sagging or len(moved) == 0:
        return moved
    normals, count = _plane_normals(len(moved), triangles, surfaces)
    size = float(np.ptp(moved, axis=0).max())
    for done in range(MAX_ROUNDS):
        length = np.zeros(len(moved))
        step = np.zeros_like(moved)
        for surface in sagging:
            ids, move = _surface_moves(moved, triangles[surface.faces], surface, normals, count)
            reach = np.linalg.norm(move, axis=1)
            longer = reach > length[ids]
            length[ids[longer]] = reach[longer]
            step[ids[longer]] = move[longer]
        now = length > (0.0 if done == 0 else ROUNDING * size)
        if not now.any():
            break
        moved[now] += step[now]
    return moved


def _plane_normals(
    count_vertices: int, faces: IntArray, surfaces: Sequence[Surface]
) -> tuple[FloatArray, IntArray]:
    """Per vertex, the unit normals of the distinct planes among ``surfaces`` that hold
    it (up to three) and how many there are (three meaning three or more)."""
    normals = np.zeros((count_vertices, 3, 3))
    count = np.zeros(count_vertices, dtype=np.int64)
    for surface in surfaces:
        if surface.kind != "plane" or surface.axis is None or not len(surface.faces):
            continue
        normal = surface.axis / np.linalg.norm(surface.axis)
        ids = np.unique(faces[surface.faces])
        parallel = np.linalg.norm(np.cross(normals[ids], normal), axis=2) <= PARALLEL
        known = (parallel & (np.arange(3) < count[ids, None])).any(axis=1)
        new = ids[~known & (count[ids] < 3)]
        normals[new, count[new]] = normal
        count[ids[~known]] = np.minimum(count[ids[~known]] + 1, 3)
    return normals, count


def _unit(vectors: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Rows of ``vectors`` scaled to unit length (zero rows stay zero) and their lengths."""
    length = np.linalg.norm(vectors, axis=-1)
    safe = np.where(length > 0, length, 1.0)
    return vectors / safe[..., None], length


def _dot(a: FloatArray, b: FloatArray) -> FloatArray:
    return np.einsum("...i,...i->...", a, b)


def _cap(
    u: FloatArray, valid: BoolArray, pinned: BoolArray, circumcentre: bool = False
) -> tuple[FloatArray, FloatArray]:
    """Per triangle (``u``: t x 3 x d unit directions of its vertices, ``valid`` those
    that count), the unit direction ``w`` of its half-space (module docstring): the middle
    of the smallest arc or cap of directions holding its valid vertices (the pairs'
    bisectors and, with ``circumcentre``, the circumcentre of the three), or, when some
    vertices are ``pinned``, the mean of their directions. Returns ``w`` (t x d) and the
    cosines ``u_i . w`` (t x 3)."""
    u = np.where(valid[..., None], u, 0.0)
    candidates = [u[:, i] + u[:, j] for i, j in _PAIRS]
    if circumcentre:
        normal = np.cross(u[:, 1] - u[:, 0], u[:, 2] - u[:, 0])
        side = np.sign(_dot(normal, u.sum(axis=1)))
        whole = np.all(valid, axis=1)
        candidates.append(np.where(whole[:, None], normal * side[:, None], 0.0))
    stacked, length = _unit(np.stack(candidates, axis=1))
    cosines = np.einsum("tkd,tcd->tck", u, stacked)
    score = np.where(valid[:, None, :], cosines, np.inf).min(axis=2)
    score = np.where(length > 0, score, -np.inf)
    w = stacked[np.arange(len(u)), score.argmax(axis=1)]
    held, held_length = _unit((u * (pinned & valid)[..., None]).sum(axis=1))
    w = np.where((held_length > 0)[:, None], held, w)
    return w, np.einsum("tkd,td->tk", u, w)


def _largest_need(local: IntArray, count: int, need: FloatArray, asks: BoolArray) -> FloatArray:
    """Per vertex, the largest of the ``need`` its triangles' corners ``local`` ask for
    (0 where none asks)."""
    out = np.zeros(count)
    np.maximum.at(out, local[asks], need[asks])
    return out


def _directions(
    default: FloatArray,
    grad: FloatArray,
    normals: FloatArray,
    count: IntArray,
    meridian: tuple[FloatArray, FloatArray] | None,
) -> tuple[FloatArray, BoolArray]:
    """Per vertex, the unit direction of its move and whether it may move (module
    docstring, "Neighbouring faces"): ``default`` off planes or where it lies in them.
    Otherwise, about an axis (``meridian``: each vertex's direction across the axis, and
    the axis), a line in its planes that keeps its direction across the axis: in one
    plane the line it cuts from the half-plane through the axis, on two planes their
    common line if it lies in that half-plane. On a sphere, the projection of
    ``default`` on its one plane, or the common line of two. The direction is turned to
    go up the constraint's gradient ``grad``, and a move in planes closer than
    ``MIN_COS`` to the surface, or none, pins the vertex."""
    move = default.copy()
    along = np.ones(len(move), dtype=bool)
    if (count >= 1).any():
        inside = np.abs(np.einsum("vkd,vd->vk", normals, default)) <= PARALLEL
        along = (inside | (np.arange(3) >= count[:, None])).all(axis=1)
    free = along | (count == 1)
    one = (count == 1) & ~along
    if one.any():
        n = normals[one, 0]
        if meridian is None:
            line = default[one] - _dot(default[one], n)[:, None] * n
        else:
            across, axis = meridian
            line = (n @ axis)[:, None] * across[one] - _dot(across[one], n)[:, None] * axis
        move[one], _ = _unit(line)
    two = (count == 2) & ~along
    if two.any():
        line, _ = _unit(np.cross(normals[two, 0], normals[two, 1]))
        move[two] = line
        if meridian is None:
            free[two] = True
        else:
            across, axis = meridian
            free[two] = np.abs(_dot(line, np.cross(across[two], axis))) <= PARALLEL
    slope = _dot(move, grad)
    move *= np.where(slope < 0, -1.0, 1.0)[:, None]
    _, grad_length = _unit(grad)
    steep = np.abs(slope) >= MIN_COS * grad_length
    return move, free & (along | steep)


def _steps(h: FloatArray, grad: FloatArray, move: FloatArray, free: BoolArray) -> FloatArray:
    """The moves ``lambda * move`` that bring the constraints ``h >= 0`` (gradient
    ``grad``) to zero along ``move``, linearised (exact where ``h`` is linear along the
    line, at least enough where it is convex)."""
    slope = _dot(move, grad)
    go = free & (h < 0) & (slope > 0)
    lam = np.where(go, -h / np.where(go, slope, 1.0), 0.0)
    return lam[:, None] * move


def _surface_moves(
    vertices: FloatArray,
    triangles: IntArray,
    surface: Surface,
    normals: FloatArray,
    count: IntArray,
) -> tuple[IntArray, FloatArray]:
    """The vertices of ``surface``'s ``triangles`` and their moves (module docstring)."""
    ids, local = np.unique(triangles, return_inverse=True)
    local = local.reshape(triangles.shape)
    points = vertices[ids]
    planes = (normals[ids], count[ids])
    if surface.kind == "sphere":
        return ids, _sphere_moves(points, local, surface, planes)
    if surface.kind == "torus":
        return ids, _torus_moves(points, local, surface, planes)
    return ids, _axial_moves(points, local, surface, planes)


def _across(
    points: FloatArray, surface: Surface
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """The unit axis, each point's distance along it from ``surface.point``, its distance
    from the axis and its unit direction across the axis (zero on the axis)."""
    assert surface.axis is not None  # surfaces of revolution have one
    axis = surface.axis / np.linalg.norm(surface.axis)
    rel = points - surface.point
    along = rel @ axis
    direction, rho = _unit(rel - np.outer(along, axis))
    return axis, along, rho, direction


def _axial_moves(
    points: FloatArray, local: IntArray, surface: Surface, planes: tuple[FloatArray, IntArray]
) -> FloatArray:
    """Moves of a concave cylinder's or cone's vertices (module docstring)."""
    axis, along, rho, across = _across(points, surface)
    if surface.kind == "cylinder":
        valid = rho > ROUNDING * surface.radius
        slope = 0.0
    else:
        slope = math.tan(surface.half_angle)
        scale = max(float(np.abs(along).max()), float(rho.max()))
        valid = (rho > ROUNDING * scale) & (along > ROUNDING * scale)
    estimate = across - slope * axis
    move, free = _directions(across, estimate, *planes, (across, axis))
    free &= valid
    _, cosines = _cap(across[local], valid[local], ~free[local])
    asks = valid[local] & free[local] & (cosines >= MIN_DOT)
    need = _largest_need(local, len(points), 1.0 / np.where(asks, cosines, 1.0), asks)
    if surface.kind == "cylinder":
        h = np.where(need > 0, rho - surface.radius * need, 0.0)
        grad = across
    else:
        tilt = need * slope
        h = np.where(need > 0, rho - tilt * along, 0.0)
        grad = across - tilt[:, None] * axis
    return _steps(h, grad, move, free)


def _sphere_moves(
    points: FloatArray, local: IntArray, surface: Surface, planes: tuple[FloatArray, IntArray]
) -> FloatArray:
    """Moves of a socket's vertices (module docstring)."""
    out, distance = _unit(points - surface.point)
    valid = distance > ROUNDING * surface.radius
    move, free = _directions(out, out, *planes, None)
    free &= valid
    _, cosines = _cap(out[local], valid[local], ~free[local], circumcentre=True)
    asks = valid[local] & free[local] & (cosines >= MIN_DOT)
    need = _largest_need(local, len(points), 1.0 / np.where(asks, cosines, 1.0), asks)
    h = np.where(need > 0, distance - surface.radius * need, 0.0)
    return _steps(h, out, move, free)


def _torus_moves(
    points: FloatArray, local: IntArray, surface: Surface, planes: tuple[FloatArray, IntArray]
) -> FloatArray:
    """Moves of a torus's vertices (module docstring)."""
    major, tube = surface.radius, surface.minor_radius
    axis, along, rho, across = _across(points, surface)
    offset = np.column_stack([rho - major, along])
    meridian, from_centre = _unit(offset)
    out = meridian[:, :1] * across + meridian[:, 1:] * axis
    valid = (rho > ROUNDING * (major + tube)) & (from_centre > ROUNDING * tube)
    corners = points[local]
    normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    male = float(np.einsum("ti,ti->", normal, out[local].sum(axis=1))) > 0
    grad = -out if male else out
    move, free = _directions(grad, grad, *planes, (across, axis))
    free &= valid
    # the sag towards the axis between vertices spread in azimuth
    _, spread = _cap(across[local], valid[local], np.zeros(local.shape, dtype=bool))
    half = np.where(valid[local], spread, 1.0).min(axis=1)
    sag = rho[local].max(axis=1) * (1.0 - np.clip(half, 0.0, 1.0))
    if male:
        reach = np.where(rho[local].min(axis=1) < major + sag, sag, 0.0)
        asks = valid[local] & free[local] & (reach > 0)[:, None]
        target = np.full(len(points), np.inf)
        np.minimum.at(
            target, local[asks], np.broadcast_to(tube - reach[:, None], local.shape)[asks]
        )
        h = np.where(np.isfinite(target), target - from_centre, 0.0)
        return _steps(h, grad, move, free)
    w, cosines = _cap(meridian[local], valid[local], ~free[local])
    beyond = tube + sag * np.maximum(w[:, 0], 0.0)
    asks = valid[local] & free[local] & (cosines >= MIN_DOT)
    need = _largest_need(local, len(points), beyond[:, None] / np.where(asks, cosines, 1.0), asks)
    h = np.where(need > 0, from_centre - need, 0.0)
    return _steps(h, grad, move, free)
