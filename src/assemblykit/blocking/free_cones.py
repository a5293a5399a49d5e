"""The exact free set of an extended translation (Wilson & Latombe 1992 §5, "Extended
translations").

Part ``j`` blocks part ``i`` along ``d`` iff the ray ``{t d, t > 0}`` enters the grown
obstacle ``P_j ⊕ (−P_i)``; the directions blocked by ``j`` are the projection of that
obstacle on the sphere, a union of open cones, one per pair of convex pieces (parts
made of convex bodies, :meth:`assemblykit.blocking.obstacles.Obstacles.cones_of`) or per
pair of triangles (any other part, :func:`assemblykit.geometry.minkowski.triangle_cones`).
The free set of a moving set is the complement of the union over its blockers.

The sphere is covered by six gnomonic charts (one per face of the cube ``|d|_∞ = 1``):
on a chart a great circle is a straight line, so each cone is a convex polygon (the
chart square clipped by the cone's half-planes, in numpy) and unions, complements and
overlays are polygon operations (shapely). A direction inside every face of the free
set (:func:`free_faces`), or of the overlay of several blocked sets
(:func:`overlay_faces`, the arrangement refined by the obstacles' boundaries), is a
candidate; the caller checks each exactly
(:func:`assemblykit.blocking.extended.extended_free`). Faces thinner than the mesh angle
tolerance are *thin*: whether they are free depends on the tolerance (a part exactly as
wide as its tunnel), and they are reported apart.

Open cones that meet without a gap leave free the directions between them: a set of
no interior, an arc of a great circle (a lid clamped between a rim and a bar slides in
their common plane) or isolated directions (a drawer between rails). Such directions
lie on a circle of a contact, or on a circle bounding cones on both sides
(:func:`sliding_circles`); on a great circle each open cone is an open arc, so the
points and arcs those arcs cut it into, and which sets hold each, are exact
(:func:`circle_cells`). A direction on every free arc and at every free point
(:func:`free_cells`), or one per combination of the sets holding such cells
(:func:`lower_cells`, part of :func:`overlay_faces`), is a candidate as well.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import shapely
from numpy.typing import NDArray

from assemblykit.algebra import se3
from assemblykit.blocking.arrangement import snap_normals
from assemblykit.blocking.cache import BlockingCache
from assemblykit.blocking.constraints import infinitesimal_terms, positively_spanning
from assemblykit.blocking.extended import extended_free
from assemblykit.blocking.obstacles import Obstacles
from assemblykit.deprecation import moved
from assemblykit.geometry.contacts import assembly_contacts
from assemblykit.geometry.minkowski import triangle_cones
from assemblykit.ragged import group_of
from assemblykit.tolerance import ModelTolerance, Tolerance

if TYPE_CHECKING:
    from assemblykit.model.assembly import Assembly

TRIANGLE_PAIRS = 16_000
"""Triangle pairs of one moving part and one obstacle beyond which the exact free set
is not computed (the answer then says it comes from sampled directions only): each
pair's cone is clipped and united in shapely, about 10 s per 10^5 pairs."""

_CHUNK = 8192


def _charts() -> NDArray[np.float64]:
    """Per chart the rows ``e, a, b``: ``d ∝ e + u a + v b`` for ``|u|, |v| <= 1``."""
    frames = []
    for axis in range(3):
        for sign in (1.0, -1.0):
            e = np.zeros(3)
            e[axis] = sign
            a = np.zeros(3)
            a[(axis + 1) % 3] = 1.0
            frames.append([e, a, np.cross(e, a)])
    return np.array(frames)


CHARTS = _charts()


def _no_cones() -> NDArray[np.float64]:
    """No cone (``0 x 1 x 3``): the empty set of directions."""
    return np.zeros((0, 1, 3))


def _no_circles() -> NDArray[np.float64]:
    """No great circle (``0 x 3`` normals)."""
    return np.zeros((0, 3))


SNAP_GRID = 1e-12
"""The grid (chart units, where the sphere's directions span about 2) to which an
overlay that GEOS's floating overlay cannot node is snapped (:func:`robust_union`): far
below any angle tolerance, it moves no vertex that decides an answer."""


def robust_union(geometries: Any) -> Any:
    """The union of ``geometries`` (shapely's ``union_all``), made robust by :func:`_robust`."""
    return _robust(shapely.union_all, geometries)


def _robust(operation: Any, *geometries: Any) -> Any:
    """``operation(*geometries)``; where near-degenerate slivers make GEOS's floating
    overlay fail (a ``TopologyException``), the same on the geometries made valid
    (``make_valid``: a sliver clipped into a bow tie becomes its two triangles), then
    also snapped to :data:`SNAP_GRID`, which GEOS's snap-rounding overlay always nodes."""
    try:
        return operation(*geometries)
    except shapely.errors.GEOSException:
        valid = [shapely.make_valid(g) for g in geometries]
    try:
        return operation(*valid)
    except shapely.errors.GEOSException:
        return operation(*valid, grid_size=SNAP_GRID)


@dataclass(frozen=True, eq=False)
class ChartSet:
    """A set of directions as one shapely geometry per chart (:data:`CHARTS`), with the
    open cones it is the union of (``cones x rows x 3``, zero rows impose nothing) and
    the normals of the contacts between the parts it stands for (``contacts``, the
    great circles a part in contact may slide along: :func:`sliding_circles`).
    ``seamed`` marks the cones of pairs of triangles: they tile each obstacle's cone, so
    where two of them meet there is no gap to look for."""

    regions: tuple[Any, ...]
    cones: NDArray[np.float64] = field(default_factory=_no_cones)
    contacts: NDArray[np.float64] = field(default_factory=_no_circles)
    seamed: NDArray[np.bool_] = field(default_factory=lambda: np.zeros(0, bool))

    @classmethod
    def from_cones(
        cls,
        normals: NDArray[np.float64],
        contacts: NDArray[np.float64] | None = None,
        seamed: NDArray[np.bool_] | None = None,
    ) -> ChartSet:
        """The union of the open cones ``{d : n . d > 0 for each row}`` (``cones x rows x 3``,
        zero rows impose nothing); ``contacts`` are kept as they are, and ``seamed``
        (default: none) marks the cones of pairs of triangles."""
        flags = np.zeros(len(normals), bool) if seamed is None else np.asarray(seamed, bool)
        whole, tiles = _distinct_cones(normals[~flags]), _distinct_cones(normals[flags])
        normals = _stacked([whole, tiles])
        regions = []
        for frame in CHARTS:
            pieces = [
                _clip(normals[lo : lo + _CHUNK], frame) for lo in range(0, len(normals), _CHUNK)
            ]
            polys = np.concatenate(pieces) if pieces else np.zeros(0, dtype=object)
            polys = polys[~shapely.is_empty(polys)]
            regions.append(robust_union(polys) if len(polys) else shapely.Polygon())
        kept = _no_circles() if contacts is None else np.asarray(contacts, dtype=np.float64)
        return cls(
            tuple(regions),
            normals.reshape(len(normals), -1, 3),
            kept.reshape(-1, 3),
            np.r_[np.zeros(len(whole), bool), np.ones(len(tiles), bool)],
        )

    @classmethod
    def everywhere(cls, contacts: NDArray[np.float64] | None = None) -> ChartSet:
        """Every direction (parts that overlap): one cone of no constraint."""
        kept = _no_circles() if contacts is None else np.asarray(contacts, dtype=np.float64)
        square = shapely.box(-1.0, -1.0, 1.0, 1.0)
        return cls(
            tuple(square for _ in CHARTS),
            np.zeros((1, 1, 3)),
            kept.reshape(-1, 3),
            np.zeros(1, bool),
        )

    @classmethod
    def union(cls, sets: Iterable[ChartSet]) -> ChartSet:
        """The union of several sets (their cones and contacts together)."""
        sets = list(sets)
        if not sets:
            return cls(tuple(shapely.Polygon() for _ in CHARTS))
        return cls(
            tuple(robust_union([s.regions[c] for s in sets]) for c in range(len(CHARTS))),
            _stacked([s.cones for s in sets]),
            np.concatenate([s.contacts for s in sets]).reshape(-1, 3),
            np.concatenate([s.seamed for s in sets]),
        )

    def contains(self, direction: NDArray[np.float64], tol: Tolerance | None = None) -> bool:
        """Whether the direction lies inside the set: inside one of its open cones, by
        more than the angle tolerance (when given) from each of the cone's circles. A
        direction where two cones meet without a gap (a part sliding between two others)
        is in neither."""
        d = np.asarray(direction, dtype=np.float64).ravel()
        d = d / np.linalg.norm(d)
        margin = 0.0 if tol is None else tol.angle
        rows = self.cones
        length = np.linalg.norm(rows, axis=2)
        dots = rows @ d
        held = (dots > margin * length) | (length == 0)
        return bool(np.any(np.all(held, axis=1)))


def _distinct_cones(normals: NDArray[np.float64]) -> NDArray[np.float64]:
    """The cones (``cones x rows x 3``) with repeats removed: a cone is the set of its
    rows' directions, so rows are scaled to unit length and put in one order before
    equal cones are merged (pairs of triangles from parallel faces repeat them often)."""
    if len(normals) < 2:
        return normals
    length = np.linalg.norm(normals, axis=2, keepdims=True)
    unit = np.where(length > 0, normals / np.where(length > 0, length, 1.0), 0.0)
    # any fixed order of the rows will do: equal rows sort together
    weight = np.array([1.0, np.sqrt(2.0), np.sqrt(3.0)])
    order = np.argsort(unit @ weight, axis=1, kind="stable")
    ordered = np.take_along_axis(unit, order[:, :, None], axis=1)
    _, first = np.unique(
        np.round(ordered.reshape(len(ordered), -1), 12) + 0.0, axis=0, return_index=True
    )
    return ordered[np.sort(first)]


def _clip(normals: NDArray[np.float64], frame: NDArray[np.float64]) -> NDArray[np.object_]:
    """The chart square clipped by each cone's half-planes ``γ + α u + β v > 0``: the
    convex polygons of all cones at once, one half-plane after another (Sutherland &
    Hodgman 1974: each vertex inside is kept, each edge crossing the line gives the
    crossing point; a convex polygon gains at most one vertex per cut). Cones whose
    polygon has no area give empty polygons."""
    e, a, b = frame
    k, rows = len(normals), normals.shape[1]
    cap = 4 + rows
    points = np.zeros((k, cap, 2))
    points[:, :4] = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]]
    count = np.full(k, 4)
    slots = np.arange(cap)[None, :]
    for r in range(rows):
        n = normals[:, r]
        gamma, alpha, beta = (n @ e)[:, None], (n @ a)[:, None], (n @ b)[:, None]
        value = gamma + alpha * points[..., 0] + beta * points[..., 1]
        valid = slots < count[:, None]
        # only polygons the line cuts change (a zero row imposes nothing)
        cut = np.flatnonzero(np.any(valid & (value <= 0), axis=1) & np.any(n != 0, axis=1))
        if not len(cut):
            continue
        value, valid, pts, left = value[cut], valid[cut], points[cut], count[cut]
        after = np.where(slots + 1 < left[:, None], slots + 1, 0)
        value_after = np.take_along_axis(value, after, axis=1)
        inside, inside_after = value > 0, value_after > 0
        crossing = valid & (inside != inside_after)
        t = value / np.where(crossing, value - value_after, 1.0)
        ahead = np.take_along_axis(pts, after[..., None], axis=1)
        hit = pts + t[..., None] * (ahead - pts)
        keep = np.stack([valid & inside, crossing], axis=2).reshape(len(cut), 2 * cap)
        emitted = np.stack([pts, hit], axis=2).reshape(len(cut), 2 * cap, 2)
        order = np.argsort(~keep, axis=1, kind="stable")[:, :cap]
        points[cut] = np.take_along_axis(emitted, order[..., None], axis=1)
        count[cut] = np.minimum(keep.sum(axis=1), cap)
    x, y = points[..., 0], points[..., 1]
    following = np.where(slots + 1 < count[:, None], slots + 1, 0)
    twice = x * np.take_along_axis(y, following, 1) - np.take_along_axis(x, following, 1) * y
    area = np.where(slots < count[:, None], twice, 0.0).sum(axis=1) / 2.0
    solid = (count >= 3) & (area > 0)
    polys = np.full(k, shapely.Polygon(), dtype=object)
    if solid.any():
        used = group_of(count[solid])
        coords = points[solid][slots[0, None, :] < count[solid][:, None]]
        polys[solid] = shapely.polygons(shapely.linearrings(coords, indices=used))
    return polys


def _to_directions(c: int, uv: NDArray[np.float64]) -> NDArray[np.float64]:
    e, a, b = CHARTS[c]
    d: NDArray[np.float64] = e[None, :] + uv[:, :1] * a[None, :] + uv[:, 1:2] * b[None, :]
    lengths: NDArray[np.float64] = np.linalg.norm(d, axis=1, keepdims=True)
    return d / lengths


@dataclass(frozen=True, eq=False)
class Faces:
    """Directions inside faces of a set of directions: ``directions`` in faces at least
    as wide as the mesh angle tolerance (widest first), ``thin`` in narrower ones."""

    directions: NDArray[np.float64]
    thin: NDArray[np.float64]


def _faces(polygons: Sequence[tuple[int, shapely.Polygon]], tol: ModelTolerance) -> Faces:
    wide: list[tuple[float, NDArray[np.float64]]] = []
    thin: list[tuple[float, NDArray[np.float64]]] = []
    for c, poly in polygons:
        if poly.is_empty or poly.area <= 0:
            continue
        # width of a strip of that area and perimeter
        width = 2.0 * poly.area / max(poly.length, 1e-300)
        point = np.array(shapely.get_coordinates(poly.representative_point())[0])
        d = _to_directions(c, point[None, :])[0]
        (wide if width > tol.mesh_angle else thin).append((width, d))
    wide.sort(key=lambda x: -x[0])
    thin.sort(key=lambda x: -x[0])
    return Faces(
        np.array([d for _, d in wide]).reshape(-1, 3), np.array([d for _, d in thin]).reshape(-1, 3)
    )


def _stacked(cones: Sequence[NDArray[np.float64]]) -> NDArray[np.float64]:
    """Cones of several sets in one array, padded with zero rows to the widest."""
    width = max((c.shape[1] for c in cones), default=1)
    padded = [np.concatenate([c, np.zeros((len(c), width - c.shape[1], 3))], axis=1) for c in cones]
    return np.concatenate(padded) if padded else np.zeros((0, width, 3))


@dataclass(frozen=True, eq=False)
class CircleCells:
    """The points and open arcs into which the boundaries of the cones of several sets
    cut some great circles (:func:`circle_cells`): a direction in each cell, its
    dimension (0 a point, 1 an arc), its length in radians (0 for a point) and which
    sets hold it (``inside``, cells x sets)."""

    directions: NDArray[np.float64]
    dims: NDArray[np.int8]
    lengths: NDArray[np.float64]
    inside: NDArray[np.bool_]


@dataclass(frozen=True, eq=False)
class _Arcs:
    """Arcs of one great circle: start angles, lengths, the cone of each and the cone
    rows whose circles end them (``bounds``: arcs x 2 x 3, start then end); ``whole``
    when a cone of no constraint covers the circle."""

    start: NDArray[np.float64]
    length: NDArray[np.float64]
    cone: NDArray[np.int64]
    bounds: NDArray[np.float64]
    whole: bool


def _arcs_on_circle(
    cones: NDArray[np.float64],
    u: NDArray[np.float64],
    v: NDArray[np.float64],
    tol: ModelTolerance,
    closed: bool = False,
) -> _Arcs:
    """Where the open cones meet the great circle ``cos t u + sin t v``: one open arc
    per cone meeting it. A row ``n`` is the open half-circle of the points within a
    quarter turn of ``n``'s projection; a row normal to the circle (within the angle
    tolerance) is zero all along it, so its cone misses the circle. With ``closed``,
    the closed arcs of the closed cones instead (a single point is an arc of length 0,
    a cone of no constraint the whole circle)."""
    if not len(cones):
        return _Arcs(np.zeros(0), np.zeros(0), np.zeros(0, np.int64), np.zeros((0, 2, 3)), False)
    norms = np.linalg.norm(cones, axis=2)
    real = norms > 0
    a, b = cones @ u, cones @ v
    parallel = real & (np.hypot(a, b) <= tol.angle * norms)
    centre = np.arctan2(b, a)
    ref = centre[np.arange(len(cones)), np.argmax(real, axis=1)]
    # each centre unwrapped to within a half turn of the cone's first one
    rel = np.mod(centre - ref[:, None] + np.pi, 2.0 * np.pi) - np.pi
    first, last = np.where(real, rel, -np.inf), np.where(real, rel, np.inf)
    some = real.any(axis=1)
    # a cone of no constraint: the whole circle
    low = np.where(some, first.max(axis=1) - np.pi / 2, 0.0)
    high = np.where(some, last.min(axis=1) + np.pi / 2, 2.0 * np.pi)
    if closed:
        keep = ~parallel.any(axis=1) & (high - low >= -tol.mesh_angle)
    else:
        keep = some & ~parallel.any(axis=1) & (high - low > tol.angle)
    k = np.arange(len(cones))
    bounds = np.stack([cones[k, first.argmax(axis=1)], cones[k, last.argmin(axis=1)]], axis=1)
    start = np.mod(ref + low, 2.0 * np.pi)[keep]
    length = np.maximum(high - low, 0.0)[keep]
    return _Arcs(start, length, k[keep], bounds[keep], bool((~some).any()))


def _arcs_meet(first: _Arcs, second: _Arcs, slack: float, chunk: int = 1 << 20) -> bool:
    """Whether some closed arc of ``first`` meets one of ``second`` (within ``slack``)."""
    step = max(1, chunk // max(len(second.start), 1))
    for lo in range(0, len(first.start), step):
        s1, l1 = first.start[lo : lo + step, None], first.length[lo : lo + step, None]
        ahead = np.mod(second.start[None, :] - s1, 2.0 * np.pi) <= l1 + slack
        behind = np.mod(s1 - second.start[None, :], 2.0 * np.pi) <= second.length[None, :] + slack
        if np.any(ahead | behind):
            return True
    return False


def _cells_of_circle(
    sets: Sequence[NDArray[np.float64]], m: NDArray[np.float64], tol: ModelTolerance
) -> CircleCells:
    """:func:`circle_cells` on one circle: the arc ends are clustered within the mesh
    angle tolerance, and the arcs of each set holding each cell are counted in one
    sweep around the circle (an arc adds one after its start, removes one at its end:
    a point where an arc ends or starts is outside it, the arcs being open)."""
    # the cells are found round the circle from u: their order and directions
    # depend on the frame's turn
    u, v = se3.axis_basis(m, turned=True)
    found = [_arcs_on_circle(c, u, v, tol) for c in sets]
    whole = np.array([f.whole for f in found], dtype=bool)
    start = np.concatenate([f.start for f in found])
    length = np.concatenate([f.length for f in found])
    bounds = np.concatenate([f.bounds for f in found])
    owner = np.concatenate([np.full(len(f.start), k) for k, f in enumerate(found)]).astype(np.int64)
    if not len(start):
        return CircleCells(u[None, :], np.ones(1, np.int8), np.full(1, 2.0 * np.pi), whole[None, :])
    ends = np.concatenate([start, np.mod(start + length, 2.0 * np.pi)])
    order = np.argsort(ends, kind="stable")
    sorted_ends = ends[order]
    new = np.r_[True, np.diff(sorted_ends) > tol.mesh_angle]
    cluster = np.empty(len(ends), np.int64)
    cluster[order] = np.cumsum(new) - 1
    count = int(cluster.max()) + 1
    positions = ends.copy()
    if count > 1 and sorted_ends[0] + 2.0 * np.pi - sorted_ends[-1] <= tol.mesh_angle:
        # the last cluster wraps round to the first
        last = cluster == count - 1
        positions[last] -= 2.0 * np.pi
        cluster[last] = 0
        count -= 1
    centres = np.bincount(cluster, positions, count) / np.bincount(cluster, minlength=count)
    following = np.r_[centres[1:], centres[0] + 2.0 * np.pi]
    middles = (centres + following) / 2.0
    n = len(start)
    opens, closes = np.zeros((count, len(sets))), np.zeros((count, len(sets)))
    np.add.at(opens, (cluster[:n], owner), 1.0)
    np.add.at(closes, (cluster[n:], owner), 1.0)
    # before the first point: the arcs holding the middle of the last cell
    before = np.zeros(len(sets))
    np.add.at(before, owner, np.mod(middles[-1] - start, 2.0 * np.pi) < length)
    after = before + np.cumsum(opens - closes, axis=0)
    at_points = np.vstack([before, after[:-1]]) - closes
    angles = np.r_[centres, middles]
    directions = np.cos(angles)[:, None] * u + np.sin(angles)[:, None] * v
    # a point lies on the circle of a row ending an arc there: their cross product
    _, member = np.unique(cluster, return_index=True)
    ending = np.concatenate([bounds[:, 0], bounds[:, 1]])[member]
    crossing = np.cross(m, ending)
    crossing /= np.linalg.norm(crossing, axis=1, keepdims=True)
    points = directions[:count]
    directions[:count] = crossing * np.sign(np.einsum("ij,ij->i", crossing, points))[:, None]
    inside = np.vstack([at_points, after]) > 0.5
    return CircleCells(
        directions,
        np.r_[np.zeros(count, np.int8), np.ones(count, np.int8)],
        np.r_[np.zeros(count), following - centres],
        inside | whole[None, :],
    )


def circle_cells(
    sets: Sequence[NDArray[np.float64]], circles: NDArray[np.float64], tol: ModelTolerance
) -> CircleCells:
    """The cells (points and open arcs) of the arrangement the cones of ``sets`` (each
    ``cones x rows x 3``) cut on each great circle of ``circles`` (unit normals), and
    which sets hold each: exact on those circles, up to the angle tolerances (Wilson &
    Latombe 1992 §5: on a circle each open cone is an open arc)."""
    parts = [_cells_of_circle(sets, m / np.linalg.norm(m), tol) for m in circles]
    if not parts:
        return CircleCells(
            np.zeros((0, 3)), np.zeros(0, np.int8), np.zeros(0), np.zeros((0, len(sets)), bool)
        )
    return CircleCells(
        np.concatenate([p.directions for p in parts]),
        np.concatenate([p.dims for p in parts]),
        np.concatenate([p.lengths for p in parts]),
        np.concatenate([p.inside for p in parts]),
    )


def sliding_circles(sets: Sequence[ChartSet], tol: ModelTolerance) -> NDArray[np.float64]:
    """The great circles where a set of directions may be thinner than a face: those of
    the contacts (a part held between two others slides along their common plane; a pin
    in its hole along its axis, where the circles of its contact meet) and those along
    which a cone on one side and a cone on the other meet (:func:`_abutting_circles`:
    obstacles leaving a gap of no width between them; the cones of pairs of triangles
    tile their obstacle's, so only contacts count for them). Where the directions outside
    some open cones have no interior, they lie on such a circle: on any other point of
    a cone's boundary, the cone lies on one side only and the other side is outside
    every cone nearby (docs/blocking.md, "Three kinds of motion")."""
    contacts = np.concatenate([s.contacts for s in sets]).reshape(-1, 3)
    cones = _stacked([s.cones[~s.seamed] for s in sets])
    candidates = np.concatenate([contacts, _abutting_circles(cones, tol)])
    if not len(candidates):
        return np.zeros((0, 3))
    return snap_normals(candidates, tol)[0]


def _abutting_circles(cones: NDArray[np.float64], tol: ModelTolerance) -> NDArray[np.float64]:
    """The circles of cone rows (snapped within the angle tolerance) that bound cones on
    both sides, where the facet (closed arc) of such a cone on one side meets that of
    one on the other: only there can the two cones leave a gap of no width."""
    length = np.linalg.norm(cones, axis=2)
    cone_of, row_of = np.nonzero(length > 0)
    if not len(cone_of):
        return np.zeros((0, 3))
    rows = cones[cone_of, row_of] / length[cone_of, row_of, None]
    # one sign per line (that of its first clearly nonzero entry), lines equal within
    # the angle tolerance joined
    lead = np.argmax(np.abs(rows) > 1e-6, axis=1)
    sign = np.sign(rows[np.arange(len(rows)), lead])
    keys, inverse = np.unique(np.round(rows * sign[:, None], 9) + 0.0, axis=0, return_inverse=True)
    leaders, group, orient = snap_normals(keys, tol)
    circle = group[inverse.ravel()]
    side = sign * orient[inverse.ravel()]
    of_row = np.full(cones.shape[:2], -1, np.int64)
    of_row[cone_of, row_of] = circle
    count = len(leaders)
    plus = np.bincount(circle[side > 0], minlength=count) > 0
    minus = np.bincount(circle[side < 0], minlength=count) > 0
    order = np.argsort(circle, kind="stable")
    begin = np.searchsorted(circle[order], np.arange(count + 1))
    found = []
    for c in np.flatnonzero(plus & minus):
        members = order[begin[c] : begin[c + 1]]
        ks, where = np.unique(cone_of[members], return_inverse=True)
        sides = np.zeros((len(ks), 2), bool)
        np.logical_or.at(sides, (where.ravel(), (side[members] < 0).astype(np.int64)), True)
        one_side = sides[:, 0] != sides[:, 1]  # a cone on both sides is empty
        ks, upper = ks[one_side], sides[one_side, 0]
        facets = np.where((of_row[ks] == c)[..., None], 0.0, cones[ks])
        # the arcs' angles are measured from u: the other turn would round them otherwise
        u, v = se3.axis_basis(leaders[c], turned=True)
        arcs = _arcs_on_circle(facets, u, v, tol, closed=True)
        above = upper[arcs.cone]
        first = _Arcs(arcs.start[above], arcs.length[above], arcs.cone[above], arcs.bounds, False)
        second = _Arcs(
            arcs.start[~above], arcs.length[~above], arcs.cone[~above], arcs.bounds, False
        )
        if _arcs_meet(first, second, tol.mesh_angle):
            found.append(leaders[c])
    return np.array(found).reshape(-1, 3)


def free_cells(blocked: ChartSet, tol: ModelTolerance) -> NDArray[np.float64]:
    """A direction in every arc and at every point of :func:`sliding_circles` outside
    ``blocked``: its free directions that lie in no face (a part that may only slide),
    longest arcs first, then points (Wilson & Latombe 1992 §5)."""
    cells = circle_cells([blocked.cones], sliding_circles([blocked], tol), tol)
    free = np.flatnonzero(~cells.inside[:, 0])
    order = free[np.lexsort((free, -cells.lengths[free]))]
    return _distinct_directions(cells.directions[order])


def _distinct_directions(directions: NDArray[np.float64]) -> NDArray[np.float64]:
    """The directions in their order, each once (a point where two circles cross is a
    cell of both)."""
    _, first = np.unique(np.round(directions, 9) + 0.0, axis=0, return_index=True)
    return directions[np.sort(first)]


def lower_cells(sets: Sequence[ChartSet], tol: ModelTolerance) -> NDArray[np.float64]:
    """One direction per distinct combination of the sets holding it among the arcs and
    points of :func:`sliding_circles` (longest first): where the sets meet without a
    gap, the combinations no face shows (a part held by fewer parts while it slides)."""
    cells = circle_cells([s.cones for s in sets], sliding_circles(sets, tol), tol)
    order = np.lexsort((np.arange(len(cells.lengths)), -cells.lengths))
    _, first = np.unique(cells.inside[order], axis=0, return_index=True)
    return cells.directions[order[np.sort(first)]]


def free_faces(blocked: ChartSet, tol: ModelTolerance) -> Faces:
    """A direction in every face of the complement of ``blocked``."""
    square = shapely.box(-1.0, -1.0, 1.0, 1.0)
    polygons: list[tuple[int, shapely.Polygon]] = []
    for c, region in enumerate(blocked.regions):
        rest = _robust(shapely.difference, square, region)
        polygons.extend((c, p) for p in shapely.get_parts(rest) if isinstance(p, shapely.Polygon))
    return _faces(polygons, tol)


def overlay_faces(sets: Sequence[ChartSet], tol: ModelTolerance, limit: int = 20_000) -> Faces:
    """A direction in every face of the overlay of the sets' boundaries (the arrangement
    refined by the obstacle boundaries), at most ``limit`` faces per chart, then one per
    combination of the sets seen only on arcs and points of :func:`sliding_circles`
    (:func:`lower_cells`): over each such cell, too, the sets holding it are constant."""
    square = shapely.box(-1.0, -1.0, 1.0, 1.0)
    polygons: list[tuple[int, shapely.Polygon]] = []
    for c in range(len(CHARTS)):
        lines = [square.boundary] + [
            s.regions[c].boundary for s in sets if not s.regions[c].is_empty
        ]
        noded = robust_union(lines)
        faces = shapely.get_parts(shapely.polygonize(shapely.get_parts(noded)))
        polygons.extend((c, p) for p in faces[:limit])
    found = _faces(polygons, tol)
    return Faces(np.vstack([found.directions, lower_cells(sets, tol)]), found.thin)


def blocked_by(
    assembly: Assembly, moving: Iterable[str], blocker: str, tol: ModelTolerance
) -> ChartSet | None:
    """The directions along which ``blocker`` blocks some part of ``moving`` (Wilson & Latombe 1992
    §5), or ``None`` when there are more triangle pairs than :data:`TRIANGLE_PAIRS`.
    Computed once per assembly, moving set, blocker and tolerance (kept in the
    assembly's :class:`~assemblykit.blocking.cache.BlockingCache`)."""
    cache = BlockingCache.of(assembly)
    key = (tuple(sorted(set(moving))), blocker, tol)
    if key not in cache.blocked:
        cache.blocked[key] = _blocked_by(assembly, cache.obstacles, key[0], blocker, tol)
    found = cache.blocked[key]
    assert found is None or isinstance(found, ChartSet)
    return found


def _blocked_by(
    assembly: Assembly, cache: Obstacles, moving: tuple[str, ...], blocker: str, tol: ModelTolerance
) -> ChartSet | None:
    """:func:`blocked_by` computed: the union of the cones of every pair of convex
    pieces, or of front and back triangles of non-convex parts, with the normals of
    the contacts between ``moving`` and ``blocker``."""
    contacts = _contact_normals(assembly, moving, blocker, tol)
    rows: list[NDArray[np.float64]] = []
    seams: list[bool] = []
    for name in moving:
        shift = cache.backout(name, blocker, tol)
        if cache.convex(name) and cache.convex(blocker):
            cones = cache.cones_of(name, blocker, tol)
            if any(len(c) == 0 for c in cones):
                # the pieces overlap (even backed out): every direction is blocked
                return ChartSet.everywhere(contacts)
            rows.extend(cones)
            seams.extend(False for _ in cones)
            continue
        a, b = assembly.parts[name].mesh, assembly.parts[blocker].mesh
        if len(a.faces) * len(b.faces) > TRIANGLE_PAIRS:
            return None
        volume = bool(a.is_volume and b.is_volume)
        step = max(1, _CHUNK // max(len(b.faces), 1))
        for lo in range(0, len(a.faces), step):
            normals, valid = triangle_cones(
                a.triangles[lo : lo + step] + shift,
                b.triangles,
                a.face_normals[lo : lo + step] if volume else None,
                b.face_normals if volume else None,
                tol,
            )
            rows.extend(normals[valid])
            seams.extend(True for _ in range(int(valid.sum())))
    if not rows:
        return ChartSet.from_cones(_no_cones(), contacts)
    width = max(len(r) for r in rows)
    padded = np.zeros((len(rows), width, 3))
    for k, r in enumerate(rows):
        padded[k, : len(r)] = r
    return ChartSet.from_cones(padded, contacts, np.array(seams, dtype=bool))


def _contact_normals(
    assembly: Assembly, moving: tuple[str, ...], blockers: str | Iterable[str], tol: ModelTolerance
) -> NDArray[np.float64]:
    """The normals of the Γ_t terms of the contacts where a part of ``blockers`` (one
    name or several) touches a part of ``moving``
    (:func:`assemblykit.blocking.constraints.infinitesimal_terms`)."""
    inside = set(moving)
    outside = {blockers} if isinstance(blockers, str) else set(blockers) - inside
    touching = [
        c
        for c in assembly_contacts(assembly, tol)
        if (c.a in inside and c.b in outside) or (c.b in inside and c.a in outside)
    ]
    rows = [
        t.normals
        for t in infinitesimal_terms(touching)
        if t.moving in inside and t.blocker in outside
    ]
    return np.concatenate(rows).reshape(-1, 3) if rows else _no_circles()


@dataclass(frozen=True, eq=False)
class ExactFree:
    """Directions along which a moving set leaves by one extended translation, from its
    exact free set. ``directions`` are checked free (widest faces first); ``complete``
    is false when the free set could not be computed (too many triangle pairs) and
    nothing was found; ``tolerance_dependent`` when the only free directions lie in
    faces thinner than the mesh angle tolerance: the set leaves only if the tolerance
    lets it touch (a part exactly as wide as its tunnel)."""

    directions: tuple[NDArray[np.float64], ...]
    complete: bool
    tolerance_dependent: bool


def blocked_sets(
    assembly: Assembly, moving: Iterable[str], among: Iterable[str], tol: ModelTolerance
) -> dict[str, ChartSet] | None:
    """Per other part of ``among``, the directions along which it blocks ``moving``
    (``None`` when one is too large to compute)."""
    movers = sorted(set(moving))
    out: dict[str, ChartSet] = {}
    for blocker in sorted(set(among) - set(movers)):
        found = blocked_by(assembly, movers, blocker, tol)
        if found is None:
            return None
        out[blocker] = found
    return out


def exact_free_directions(
    assembly: Assembly,
    moving: Iterable[str],
    tol: ModelTolerance,
    among: Iterable[str] | None = None,
    limit: int = 8,
) -> ExactFree:
    """Up to ``limit`` directions, one per face of the free set of ``moving`` among the
    parts ``among`` (default: all), each checked exactly (Wilson & Latombe 1992 §5).
    When no face is free, one per free arc and free point of :func:`sliding_circles`
    (:func:`free_cells`: a set that may only slide), then the thin faces. None, with
    no cone computed, when the normals of the contacts of ``moving`` with the others
    positively span space (:func:`~assemblykit.blocking.constraints.positively_spanning`:
    it cannot start to move)."""
    movers = sorted(set(moving))
    others = list(assembly.names if among is None else among)
    if positively_spanning(_contact_normals(assembly, tuple(movers), others, tol)):
        # its contacts alone hold it in every direction: its free set is empty
        return ExactFree((), True, False)
    sets = blocked_sets(assembly, movers, others, tol)
    if sets is None:
        return ExactFree((), False, False)
    faces = free_faces(ChartSet.union(sets.values()), tol)
    found = [d for d in faces.directions if extended_free(assembly, movers, d, tol, others)]
    if found:
        return ExactFree(tuple(found[:limit]), True, False)
    for d in free_cells(ChartSet.union(sets.values()), tol):
        if extended_free(assembly, movers, d, tol, others):
            found.append(d)
            if len(found) == limit:
                break
    if found:
        return ExactFree(tuple(found), True, False)
    thin = [d for d in faces.thin[:limit] if extended_free(assembly, movers, d, tol, others)]
    return ExactFree(tuple(thin), True, bool(thin))


LATTICE_LOCK_PARTS = 8
"""The most parts a set may have for :func:`lattice_locked` to examine each of its
subsets (``2^n - 2`` of them, one bit per ordered pair of parts in 64); larger sets
are left to the faces and cells above."""


def _primitive(vectors: NDArray[np.int64]) -> NDArray[np.int64]:
    """Nonzero integer vectors divided by their gcd, sign fixed (first nonzero entry
    positive), each once: one per line through the origin."""
    kept = vectors[np.any(vectors != 0, axis=1)]
    kept = kept // np.gcd.reduce(np.abs(kept), axis=1)[:, None]
    lead = kept[np.arange(len(kept)), np.argmax(kept != 0, axis=1)]
    return np.unique(kept * np.sign(lead)[:, None], axis=0)


def _box_circles(offsets: NDArray[np.int64]) -> NDArray[np.int64]:
    """The great circles bounding the cones of the open boxes ``(o - 1, o + 1)^3``: the
    planes through the origin and an edge of a box, an edge along axis ``k`` through the
    lattice point ``p e_i + q e_j`` giving the normal ``p e_j - q e_i`` (``k, i, j``
    cyclic). Integer normals, each circle once."""
    normals = []
    for k in range(3):
        i, j = (k + 1) % 3, (k + 2) % 3
        for si in (-1, 1):
            for sj in (-1, 1):
                n = np.zeros((len(offsets), 3), np.int64)
                n[:, i] = -(offsets[:, j] + sj)
                n[:, j] = offsets[:, i] + si
                normals.append(n)
    return _primitive(np.concatenate(normals))


def _vertices(circles: NDArray[np.int64]) -> NDArray[np.int64]:
    """Every point where two of the circles cross (both antipodes), integer vectors."""
    first, second = np.triu_indices(len(circles), 1)
    crossings = _primitive(np.cross(circles[first], circles[second]))
    return np.unique(np.concatenate([crossings, -crossings]), axis=0)


def _near_points(directions: NDArray[np.int64], reach: int) -> NDArray[np.int64]:
    """``directions x samples x 8 x 3``: lattice points ``o`` with ``|t d - o|_∞ < 1`` for
    some ``t > 0``, as many as the ray passes near while it stays within ``reach`` of the
    origin. Between two consecutive ``t`` where a coordinate of ``t d`` is an integer the
    points within an open unit of ``t d`` do not change (per axis the two integers around
    a coordinate that is not one, ``0`` along an axis where ``d`` is 0), and at such a
    ``t`` they are fewer, so one ``t`` per interval, its middle, sees them all."""
    size = np.abs(directions).astype(np.float64)
    steps = np.arange(reach + 2, dtype=np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        times = steps[None, None, :] / size[:, :, None]
    times = np.sort(times.reshape(len(directions), -1), axis=1)
    middles = (times[:, :-1] + times[:, 1:]) / 2.0
    middles = np.where(np.isfinite(middles) & (times[:, 1:] > times[:, :-1]), middles, np.nan)
    along = middles[:, :, None] * directions[:, None, :]
    low = np.where(directions[:, None, :] == 0, 0.0, np.floor(along))
    high = np.where(directions[:, None, :] == 0, 0.0, low + 1.0)
    corners = np.array([[(c >> k) & 1 for k in range(3)] for c in range(8)], bool)
    points = np.where(corners[None, None], high[:, :, None, :], low[:, :, None, :])
    points = np.where(np.isnan(points), reach + 1.0, points)
    return points.astype(np.int64)


def lattice_locked(cells: Sequence[NDArray[np.int64]], chunk: int = 1024) -> bool:
    """Whether no set of the parts, each a union of unit cells (:func:`lattice_cells`),
    leaves the others by one extended translation, whatever its direction: a certificate
    of interlock that needs no overlay of free sets (docs/blocking.md, "Three kinds of
    motion", parts made of voxels).

    Cell ``a`` of a moving part sweeps into cell ``b`` of a still one along ``d`` iff the
    ray ``t d`` enters the open box ``(b - a - 1, b - a + 1)^3`` (Wilson & Latombe 1992
    §5: the grown obstacle of two cubes), so each set's blocked directions are a union of
    open cones bounded by the circles through the boxes' edges (:func:`_box_circles`).
    Its free directions, the complement, are closed; each component is bounded by arcs
    of those circles and so holds a point where two of them cross, its corner (a
    component without corners is a closed hemisphere or a circle, which another circle
    crosses). A set is therefore stuck iff every such crossing (:func:`_vertices`) lies
    in a blocked cone; which boxes a crossing's ray enters is read off the lattice
    points it passes near (:func:`_near_points`). Sets of more than
    :data:`LATTICE_LOCK_PARTS` parts are not examined (``False``)."""
    n = len(cells)
    if n < 2 or n > LATTICE_LOCK_PARTS:
        return False
    every = np.concatenate(cells)
    reach = int((every.max(axis=0) - every.min(axis=0)).max())  # the farthest offset
    width = 2 * reach + 1
    # per lattice offset b - a: bit n i + j when a cell of i and one of j are that far apart
    table = np.zeros((width, width, width), np.uint64)
    offsets = []
    for i in range(n):
        for j in range(n):
            if i != j:
                found = np.unique((cells[j][None] - cells[i][:, None]).reshape(-1, 3), axis=0)
                x, y, z = (found + reach).T
                table[x, y, z] |= np.uint64(1 << (n * i + j))
                offsets.append(found)
    circles = _box_circles(np.unique(np.concatenate(offsets), axis=0))
    if len(circles) < 2:
        return False
    vertices = _vertices(circles)
    held = np.zeros(len(vertices), np.uint64)
    for lo in range(0, len(vertices), chunk):
        points = _near_points(vertices[lo : lo + chunk], reach)
        inside = np.all(np.abs(points) <= reach, axis=3)
        x, y, z = np.moveaxis(np.clip(points + reach, 0, width - 1), 3, 0)
        bits = np.where(inside, table[x, y, z], np.uint64(0))
        held[lo : lo + chunk] = np.bitwise_or.reduce(bits.reshape(len(bits), -1), axis=1)
    everything = (1 << n) - 1
    for subset in range(1, everything):
        leaving = 0
        for i in range(n):
            if subset >> i & 1:
                leaving |= (everything & ~subset) << (n * i)
        if not np.all(held & np.uint64(leaving)):
            return False
    return True


__getattr__ = moved(__name__, {"lattice_cells": "assemblykit.blocking.lattice"})
