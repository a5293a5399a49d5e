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
chart square clipped by the cone's half-planes) and unions, complements and overlays
are polygon operations (shapely). A direction inside every face of the free set
(:func:`free_directions`), or of the overlay of several blocked sets
(:func:`overlay_directions`, the arrangement refined by the obstacles' boundaries), is
a candidate; the caller checks each exactly
(:func:`assemblykit.blocking.extended.extended_free`). Faces thinner than the mesh angle
tolerance are *thin*: whether they are free depends on the tolerance (a part exactly as
wide as its tunnel), and they are reported apart.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import shapely
from numpy.typing import NDArray

from assemblykit.blocking.cache import BlockingCache
from assemblykit.blocking.extended import extended_free
from assemblykit.blocking.obstacles import Obstacles
from assemblykit.geometry.minkowski import triangle_cones
from assemblykit.tolerance import Tolerance

if TYPE_CHECKING:
    from assemblykit.model.assembly import Assembly

TRIANGLE_PAIRS = 16_000
"""Triangle pairs of one moving part and one obstacle beyond which the exact free set
is not computed (the answer then says it comes from sampled directions only): each
pair's cone is clipped and united in shapely, about 10 s per 10^5 pairs."""

_CHUNK = 8192
_HALF_PLANE = 8.0
"""Half-size of the quadrilateral standing for a half-plane (the chart square is
``[-1, 1]²``, lines farther than 3 from its centre are moved to 3)."""


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


@dataclass(frozen=True, eq=False)
class ChartSet:
    """A set of directions as one shapely geometry per chart (:data:`CHARTS`)."""

    regions: tuple[Any, ...]

    @classmethod
    def from_cones(cls, normals: NDArray[np.float64]) -> ChartSet:
        """The union of the open cones ``{d : n . d > 0 for each row}`` (``cones x rows x 3``,
        zero rows impose nothing)."""
        normals = _distinct_cones(normals)
        regions = []
        for frame in CHARTS:
            pieces = [
                _clip(normals[lo : lo + _CHUNK], frame) for lo in range(0, len(normals), _CHUNK)
            ]
            polys = np.concatenate(pieces) if pieces else np.zeros(0, dtype=object)
            polys = polys[~shapely.is_empty(polys)]
            regions.append(shapely.union_all(polys) if len(polys) else shapely.Polygon())
        return cls(tuple(regions))

    @classmethod
    def union(cls, sets: Iterable[ChartSet]) -> ChartSet:
        """The union of several sets."""
        sets = list(sets)
        if not sets:
            return cls(tuple(shapely.Polygon() for _ in CHARTS))
        return cls(
            tuple(shapely.union_all([s.regions[c] for s in sets]) for c in range(len(CHARTS)))
        )

    def contains(self, direction: NDArray[np.float64]) -> bool:
        """Whether the direction lies inside the set (not on its boundary)."""
        c, uv = _chart_point(direction)
        return bool(self.regions[c].contains(shapely.Point(*uv)))


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
    """The chart square clipped by each cone's half-planes ``γ + α u + β v > 0``."""
    e, a, b = frame
    polys = shapely.box(-1.0, -1.0, 1.0, 1.0)
    polys = np.full(len(normals), polys, dtype=object)
    for r in range(normals.shape[1]):
        n = normals[:, r]
        gamma, alpha, beta = n @ e, n @ a, n @ b
        length = np.hypot(alpha, beta)
        free = length <= 1e-300
        m = np.column_stack([alpha, beta]) / np.where(free, 1.0, length)[:, None]
        # a line far from the square cuts it as a line at distance 3 does: not at all
        c = np.clip(gamma / np.where(free, 1.0, length), -3.0, 3.0)
        foot = -c[:, None] * m
        t = np.column_stack([-m[:, 1], m[:, 0]])
        h = _HALF_PLANE
        quad = np.stack([foot - h * t, foot + h * t, foot + h * t + h * m, foot - h * t + h * m], 1)
        halves = shapely.polygons(quad)
        # a zero row, or a row parallel to e, is all or nothing
        everywhere = free & (gamma > 0) | (np.linalg.norm(n, axis=1) == 0)
        nowhere = free & (gamma <= 0) & ~everywhere
        cut = ~everywhere & ~nowhere
        if cut.any():
            polys[cut] = shapely.intersection(polys[cut], halves[cut])
        polys[nowhere] = shapely.Polygon()
    return polys


def _chart_point(direction: NDArray[np.float64]) -> tuple[int, NDArray[np.float64]]:
    d = np.asarray(direction, dtype=np.float64).ravel()
    axis = int(np.argmax(np.abs(d)))
    c = 2 * axis + (0 if d[axis] > 0 else 1)
    e, a, b = CHARTS[c]
    scale = d @ e
    return c, np.array([d @ a, d @ b]) / scale


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


def _faces(polygons: Sequence[tuple[int, shapely.Polygon]], tol: Tolerance) -> Faces:
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


def free_faces(blocked: ChartSet, tol: Tolerance) -> Faces:
    """A direction in every face of the complement of ``blocked``."""
    square = shapely.box(-1.0, -1.0, 1.0, 1.0)
    polygons: list[tuple[int, shapely.Polygon]] = []
    for c, region in enumerate(blocked.regions):
        rest = shapely.difference(square, region)
        polygons.extend((c, p) for p in shapely.get_parts(rest) if isinstance(p, shapely.Polygon))
    return _faces(polygons, tol)


def overlay_faces(sets: Sequence[ChartSet], tol: Tolerance, limit: int = 20_000) -> Faces:
    """A direction in every face of the overlay of the sets' boundaries (the arrangement
    refined by the obstacle boundaries), at most ``limit`` faces per chart."""
    square = shapely.box(-1.0, -1.0, 1.0, 1.0)
    polygons: list[tuple[int, shapely.Polygon]] = []
    for c in range(len(CHARTS)):
        lines = [square.boundary] + [
            s.regions[c].boundary for s in sets if not s.regions[c].is_empty
        ]
        noded = shapely.union_all(lines)
        faces = shapely.get_parts(shapely.polygonize(shapely.get_parts(noded)))
        polygons.extend((c, p) for p in faces[:limit])
    return _faces(polygons, tol)


def blocked_by(
    assembly: Assembly, moving: Iterable[str], blocker: str, tol: Tolerance
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
    assembly: Assembly, cache: Obstacles, moving: tuple[str, ...], blocker: str, tol: Tolerance
) -> ChartSet | None:
    """:func:`blocked_by` computed: the union of the cones of every pair of convex
    pieces, or of front and back triangles of non-convex parts."""
    rows: list[NDArray[np.float64]] = []
    for name in moving:
        shift = cache.backout(name, blocker, tol)
        if cache.convex(name) and cache.convex(blocker):
            cones = cache.cones_of(name, blocker, tol)
            if any(len(c) == 0 for c in cones):
                # the pieces overlap (even backed out): every direction is blocked
                return ChartSet(tuple(shapely.box(-1.0, -1.0, 1.0, 1.0) for _ in CHARTS))
            rows.extend(cones)
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
    if not rows:
        return ChartSet.union([])
    width = max(len(r) for r in rows)
    padded = np.zeros((len(rows), width, 3))
    for k, r in enumerate(rows):
        padded[k, : len(r)] = r
    return ChartSet.from_cones(padded)


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
    assembly: Assembly, moving: Iterable[str], among: Iterable[str], tol: Tolerance
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
    tol: Tolerance,
    among: Iterable[str] | None = None,
    limit: int = 8,
) -> ExactFree:
    """Up to ``limit`` directions, one per face of the free set of ``moving`` among the
    parts ``among`` (default: all), each checked exactly (Wilson & Latombe 1992 §5)."""
    movers = sorted(set(moving))
    others = list(assembly.names if among is None else among)
    sets = blocked_sets(assembly, movers, others, tol)
    if sets is None:
        return ExactFree((), False, False)
    faces = free_faces(ChartSet.union(sets.values()), tol)
    found = [d for d in faces.directions if extended_free(assembly, movers, d, tol, others)]
    if found:
        return ExactFree(tuple(found[:limit]), True, False)
    thin = [d for d in faces.thin[:limit] if extended_free(assembly, movers, d, tol, others)]
    return ExactFree(tuple(thin), True, bool(thin))
