"""Characteristic invariants, their stabilisers and transporters (docs/algebra.md §2.4-§2.5).

A TR group is the stabiliser of a tuple of geometric objects (points, directed lines,
oriented planes, free directions). A relation between two bodies is the transporter
{X : X . sources[i] = targets[i]} = Stab(targets) . X0, with X0 built from frames made
by the *same* rule on both tuples (§2.5 "Closed form through characteristic invariants").
"""

from __future__ import annotations

import functools
import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from enum import StrEnum
from typing import Any, TypeVar

import numpy as np
from numpy.typing import NDArray

from assemblykit.algebra import se3
from assemblykit.algebra.connected_meets import tr_meet
from assemblykit.algebra.groups import SymmetryGroup
from assemblykit.algebra.lie import Kind
from assemblykit.algebra.subspaces import Vec3, psd_solve
from assemblykit.errors import FeatureError
from assemblykit.tolerance import Tolerance, current

__all__ = [
    "DirectionInvariant",
    "Invariant",
    "LineInvariant",
    "Mismatch",
    "MismatchKind",
    "PlaneInvariant",
    "PointInvariant",
    "characteristic_invariants",
    "congruence_mismatch",
    "pair_frame",
    "transform_invariant",
    "tuple_frame",
]


class MismatchKind(StrEnum):
    """What a failed test measured (docs/algebra.md §2.5 congruence tests, §4 feature
    parameters, the numeric fallback's residual)."""

    ANGLE = "angle"
    DISTANCE = "distance"
    RADIUS = "radius"
    MOMENT = "moment"
    HANDEDNESS = "handedness"
    PITCH = "pitch"
    SIDES = "sides"
    SIZE = "size"
    TYPE = "type"
    RESIDUAL = "residual"


@dataclass(frozen=True)
class Mismatch:
    """Why a set is empty: the :class:`MismatchKind` measured, its size (radians or
    model units) and a one-line message."""

    kind: MismatchKind
    value: float
    message: str


def _vec(v: Any) -> NDArray[np.float64]:
    a = np.asarray(v, dtype=np.float64)
    if a.shape != (3,):
        a = a.reshape(3)
    if not (math.isfinite(a[0]) and math.isfinite(a[1]) and math.isfinite(a[2])):
        raise FeatureError(f"non-finite coordinates {a.tolist()}")
    return a


def _direction(v: Any, what: str) -> NDArray[np.float64]:
    a = _vec(v)
    if not float(a @ a) > 0.0:
        raise FeatureError(f"zero {what} vector")
    return se3.unit(a)


@dataclass(frozen=True, eq=False)
class PointInvariant:
    """A point (stabiliser S(point))."""

    point: NDArray[np.float64]

    def __post_init__(self) -> None:
        object.__setattr__(self, "point", _vec(self.point))


@dataclass(frozen=True, eq=False)
class LineInvariant:
    """A line through ``point`` along ``direction``; directed lines have stabiliser C,
    undirected ones C ⋊ Z2 (a half-turn flip)."""

    point: NDArray[np.float64]
    direction: NDArray[np.float64]
    directed: bool = True

    def __post_init__(self) -> None:
        object.__setattr__(self, "point", _vec(self.point))
        object.__setattr__(self, "direction", _direction(self.direction, "line direction"))


@dataclass(frozen=True, eq=False)
class PlaneInvariant:
    """An oriented plane through ``point`` with unit ``normal`` (stabiliser G(normal))."""

    point: NDArray[np.float64]
    normal: NDArray[np.float64]

    def __post_init__(self) -> None:
        object.__setattr__(self, "point", _vec(self.point))
        object.__setattr__(self, "normal", _direction(self.normal, "plane normal"))


@dataclass(frozen=True, eq=False)
class DirectionInvariant:
    """A free unit vector (stabiliser X(direction))."""

    direction: NDArray[np.float64]

    def __post_init__(self) -> None:
        object.__setattr__(self, "direction", _direction(self.direction, "direction"))


Invariant = PointInvariant | LineInvariant | PlaneInvariant | DirectionInvariant


_I = TypeVar("_I", bound=Invariant)


def _trusted(cls: type[_I], **fields: Any) -> _I:
    """An invariant from data already known to be finite and normalised (skips checks:
    transformed and characteristic invariants are built in the hot path)."""
    out = object.__new__(cls)
    for name, value in fields.items():
        object.__setattr__(out, name, value)
    return out


def transform_invariant(t: NDArray[np.float64], inv: Invariant) -> Invariant:
    """The invariant moved by the rigid transform ``t``."""
    r, p = t[:3, :3], t[:3, 3]
    if isinstance(inv, PointInvariant):
        return _trusted(PointInvariant, point=r @ inv.point + p)
    if isinstance(inv, LineInvariant):
        return _trusted(
            LineInvariant,
            point=r @ inv.point + p,
            direction=r @ inv.direction,
            directed=inv.directed,
        )
    if isinstance(inv, PlaneInvariant):
        return _trusted(PlaneInvariant, point=r @ inv.point + p, normal=r @ inv.normal)
    return _trusted(DirectionInvariant, direction=r @ inv.direction)


# ----------------------------------------------------------------------------- congruence


def _dot(a: Vec3, b: Vec3) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _cross(a: Vec3, b: Vec3) -> Vec3:
    return a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]


def _minus(a: Vec3, b: Vec3) -> Vec3:
    return a[0] - b[0], a[1] - b[1], a[2] - b[2]


def _length(v: Vec3) -> float:
    return math.sqrt(_dot(v, v))


def _across(v: Vec3, u: Vec3) -> float:
    """The length of the part of ``v`` normal to the unit vector ``u``."""
    along = _dot(v, u)
    return _length((v[0] - along * u[0], v[1] - along * u[1], v[2] - along * u[2]))


def _pair_measures(a: Invariant, b: Invariant, tol: Tolerance) -> list[tuple[MismatchKind, float]]:
    """The congruence measures of one pair (§2.5 table, "congruence test" column), in
    scalar arithmetic on the invariants' coordinates (:func:`_flat`)."""
    out: list[tuple[MismatchKind, float]] = []
    (ka, pa, ua), (kb, pb, ub) = _flat(a), _flat(b)
    if ua is not None and ub is not None:
        out.append((MismatchKind.ANGLE, math.atan2(_length(_cross(ua, ub)), _dot(ua, ub))))
    if kb == _POINT and ka != _POINT:
        (ka, pa, ua), (kb, pb, ub) = (kb, pb, ub), (ka, pa, ua)
    if ka == _POINT:
        assert pa is not None
        if kb == _POINT:
            assert pb is not None
            out.append((MismatchKind.DISTANCE, _length(_minus(pb, pa))))
        elif kb == _LINE:
            assert pb is not None and ub is not None
            out.append((MismatchKind.DISTANCE, _across(_minus(pa, pb), ub)))
        elif kb == _PLANE:
            assert pb is not None and ub is not None
            out.append((MismatchKind.DISTANCE, _dot(ub, _minus(pa, pb))))
        return out
    lines = (a, b)
    if ka == _PLANE and kb == _LINE:
        (ka, pa, ua), (kb, pb, ub) = (kb, pb, ub), (ka, pa, ua)
        lines = (b, a)
    if ka == _DIRECTION or kb == _DIRECTION:
        return out
    assert pa is not None and ua is not None and pb is not None and ub is not None
    if ka == _LINE and kb == _LINE:
        cross = _cross(ua, ub)
        norm = _length(cross)
        offset = _minus(pb, pa)
        if norm <= tol.angle:
            out.append((MismatchKind.DISTANCE, _across(offset, ua)))
        else:
            signed = _dot(cross, offset) / norm
            out.append((MismatchKind.DISTANCE, abs(signed)))
            first, second = lines
            assert isinstance(first, LineInvariant) and isinstance(second, LineInvariant)
            if first.directed and second.directed:
                out.append((MismatchKind.MOMENT, signed))
    elif ka == _LINE and kb == _PLANE:
        if abs(_dot(ua, ub)) <= tol.angle:
            out.append((MismatchKind.DISTANCE, _dot(ub, _minus(pa, pb))))
    elif ka == _PLANE and kb == _PLANE and _length(_cross(ua, ub)) <= tol.angle:
        out.append((MismatchKind.DISTANCE, _dot(ua, _minus(pb, pa))))
    return out


_NOUNS: dict[type, str] = {
    PointInvariant: "point",
    LineInvariant: "axis",
    PlaneInvariant: "plane",
    DirectionInvariant: "direction",
}


def _elements(invariants: Sequence[Invariant], i: int, j: int) -> str:
    """Invariants ``i`` and ``j`` of a feature in words: ``the axis and the plane``, or
    ``planes 1 and 2`` when they are of one kind (numbered among the feature's own)."""
    nouns = [_NOUNS[type(v)] for v in invariants]
    if nouns[i] != nouns[j]:
        return f"the {nouns[i]} and the {nouns[j]}"
    rank = [k for k in range(len(nouns)) if nouns[k] == nouns[i]]
    plural = "axes" if nouns[i] == "axis" else f"{nouns[i]}s"
    return f"{plural} {rank.index(i) + 1} and {rank.index(j) + 1}"


def _describe_mismatch(kind: MismatchKind, value: float, between: str) -> Mismatch:
    where = f"between {between}"
    if kind is MismatchKind.ANGLE:
        text = f"angle mismatch {math.degrees(value):.6g}° {where}"
    elif kind is MismatchKind.MOMENT:
        text = f"moment (handedness) mismatch {value:.6g} {where}"
    else:
        text = f"{kind} mismatch {value:.6g} {where}"
    return Mismatch(kind, value, text)


def _shape_mismatch(targets: Any, sources: Any) -> Mismatch | None:
    """A "type" mismatch when the tuples differ in length or in invariant types."""
    if len(targets) != len(sources):
        return Mismatch(
            MismatchKind.TYPE, float(abs(len(targets) - len(sources))), "different counts"
        )
    for i, (t, s) in enumerate(zip(targets, sources, strict=True)):
        if type(t) is not type(s):
            return Mismatch(
                MismatchKind.TYPE, 1.0, f"invariant {i}: {type(t).__name__} vs {type(s).__name__}"
            )
    return None


def congruence_mismatch(
    targets: tuple[Invariant, ...] | list[Invariant],
    sources: tuple[Invariant, ...] | list[Invariant],
    tol: Tolerance | None = None,
) -> Mismatch | None:
    """The first failing pairwise congruence test (angles, distances, signed moments),
    or ``None`` when every pair agrees (docs/algebra.md §2.5)."""
    tol = tol or current()
    shape = _shape_mismatch(targets, sources)
    if shape is not None:
        return shape
    for i, j in itertools.combinations(range(len(targets)), 2):
        mt = _pair_measures(targets[i], targets[j], tol)
        ms = _pair_measures(sources[i], sources[j], tol)
        for (kind, vt), (_, vs) in zip(mt, ms, strict=False):
            limit = tol.angle if kind is MismatchKind.ANGLE else tol.length
            if abs(vt - vs) > limit:
                return _describe_mismatch(kind, abs(vt - vs), _elements(targets, i, j))
        if len(mt) != len(ms):
            return _describe_mismatch(MismatchKind.ANGLE, 0.0, _elements(targets, i, j))
    return None


# ----------------------------------------------------------------------------- frames


_POINT, _LINE, _PLANE, _DIRECTION = range(4)
# An invariant as Python floats: (type code, point or None, direction/normal or None).
_Flat = tuple[int, Vec3 | None, Vec3 | None]


def _flat(inv: Invariant) -> _Flat:
    """The invariant's coordinates as floats (the frame rule runs in scalar arithmetic),
    cached on the (immutable) invariant."""
    cached = inv.__dict__.get("_flat")
    if cached is None:
        cached = _flatten(inv)
        inv.__dict__["_flat"] = cached
    return cached


def _flatten(inv: Invariant) -> _Flat:
    if isinstance(inv, PointInvariant):
        return _POINT, se3.as_floats(inv.point), None
    if isinstance(inv, LineInvariant):
        return _LINE, se3.as_floats(inv.point), se3.as_floats(inv.direction)
    if isinstance(inv, PlaneInvariant):
        return _PLANE, se3.as_floats(inv.point), se3.as_floats(inv.normal)
    return _DIRECTION, None, se3.as_floats(inv.direction)


def _offset(code: int, p: Vec3, u: Vec3 | None, o: Vec3) -> Vec3:
    """The component of ``p - o`` normal to the object's affine set (projector applied)."""
    d0, d1, d2 = p[0] - o[0], p[1] - o[1], p[2] - o[2]
    if code == _POINT:
        return d0, d1, d2
    assert u is not None
    along = u[0] * d0 + u[1] * d1 + u[2] * d2
    if code == _LINE:
        return d0 - along * u[0], d1 - along * u[1], d2 - along * u[2]
    return along * u[0], along * u[1], along * u[2]


def _frame_columns(
    flats: tuple[_Flat, ...], tol: Tolerance
) -> tuple[Vec3, Vec3, Vec3, Vec3] | tuple[Vec3]:
    """The columns (x, y, z, origin) of :func:`tuple_frame`, or only (origin,) when the
    tuple has no direction at all (scalar arithmetic: the hot path of every transporter)."""
    m00 = m01 = m02 = m11 = m12 = m22 = r0 = r1 = r2 = 0.0
    dirs: list[Vec3] = []
    for code, p, u in flats:
        if u is not None:
            dirs.append(u)
        if code == _POINT:
            assert p is not None
            m00, m11, m22 = m00 + 1.0, m11 + 1.0, m22 + 1.0
            r0, r1, r2 = r0 + p[0], r1 + p[1], r2 + p[2]
        elif code != _DIRECTION:
            assert p is not None and u is not None
            u0, u1, u2 = u
            along = u0 * p[0] + u1 * p[1] + u2 * p[2]
            # Line: projector I - u u^T; plane: n n^T.
            sign, base = (-1.0, 1.0) if code == _LINE else (1.0, 0.0)
            m00 += base + sign * u0 * u0
            m11 += base + sign * u1 * u1
            m22 += base + sign * u2 * u2
            m01 += sign * u0 * u1
            m02 += sign * u0 * u2
            m12 += sign * u1 * u2
            if code == _LINE:
                r0, r1, r2 = r0 + p[0] - along * u0, r1 + p[1] - along * u1, r2 + p[2] - along * u2
            else:
                r0, r1, r2 = r0 + along * u0, r1 + along * u1, r2 + along * u2
    origin = psd_solve((m00, m01, m02, m11, m12, m22), (r0, r1, r2), tol)
    length, angle = tol.length, tol.angle
    # offsets below the tolerance are kept aside with their weight (length over scale)
    faint: list[tuple[float, Vec3]] = []
    for code, p, u in flats:
        if code != _DIRECTION:
            assert p is not None
            w0, w1, w2 = _offset(code, p, u, origin)
            size = math.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
            if size > length:
                dirs.append((w0 / size, w1 / size, w2 / size))
            elif size > 0.0:
                faint.append((size / tol.scale, (w0 / size, w1 / size, w2 / size)))
    if not dirs:
        return (origin,)
    z0, z1, z2 = z = dirs[0]
    hint = None
    strongest = tol.precision
    for d0, d1, d2 in dirs[1:]:
        c0, c1, c2 = z1 * d2 - z2 * d1, z2 * d0 - z0 * d2, z0 * d1 - z1 * d0
        if math.sqrt(c0 * c0 + c1 * c1 + c2 * c2) > angle:
            hint = (d0, d1, d2)
            break
    else:
        # Nothing clears the tolerance: orient by the strongest direction above rounding
        # (a pin tilted by rounded numbers), so that two congruent tuples get frames that
        # correspond; any rotation that the tolerance cannot see is in the stabiliser.
        for weight, (d0, d1, d2) in [(1.0, d) for d in dirs[1:]] + faint:
            c0, c1, c2 = z1 * d2 - z2 * d1, z2 * d0 - z0 * d2, z0 * d1 - z1 * d0
            strength = weight * math.sqrt(c0 * c0 + c1 * c1 + c2 * c2)
            if strength > strongest:
                strongest, hint = strength, (d0, d1, d2)
    return se3.frame_from_floats(origin, z, hint)


def tuple_frame(
    invariants: tuple[Invariant, ...] | list[Invariant], tol: Tolerance
) -> NDArray[np.float64]:
    """A frame built from the tuple by a rule that commutes with rigid motions up to the
    tuple's stabiliser (§2.5: "the same rule on both sides").

    Origin: the least-squares point nearest to all points, lines and planes (minimum
    norm along the directions every object contains). Axes: the first intrinsic
    direction (line, normal, free direction) or offset from the origin to an object is
    +z; the first one not parallel to it fixes +x.
    """
    columns = _frame_columns(tuple(_flat(i) for i in invariants), tol)
    if len(columns) == 1:
        return se3.translation(columns[0])
    return se3.matrix_from_columns(columns)


def pair_frame(
    first: Invariant, second: Invariant, tol: Tolerance | None = None
) -> NDArray[np.float64]:
    """The §2.5 pair frame of two invariants (``tuple_frame`` of the pair)."""
    return tuple_frame((first, second), tol or current())


# ----------------------------------------------------------------------------- stabilisers


def _single_stabilizer(inv: Invariant) -> SymmetryGroup:
    if isinstance(inv, PointInvariant):
        return SymmetryGroup.spherical(inv.point)
    if isinstance(inv, LineInvariant):
        return SymmetryGroup.cylindrical(inv.point, inv.direction)
    if isinstance(inv, PlaneInvariant):
        return SymmetryGroup(Kind.PLANAR, se3.frame(inv.point, inv.normal))
    return SymmetryGroup.schoenflies(inv.direction)


def directed_stabilizer(invariants: tuple[Invariant, ...], tol: Tolerance) -> SymmetryGroup:
    """Stab of the tuple with every line taken as directed: the meet of the TR stabilisers."""
    if not invariants:
        return SymmetryGroup.free()
    group = _single_stabilizer(invariants[0])
    for inv in invariants[1:]:
        group = tr_meet(group, _single_stabilizer(inv), tol)
    return group


# The objects of a group frame (origin o, axes x, y, z) whose directed stabiliser is the
# connected TR group of each kind (§2.4 characteristic-invariant view), as (type code,
# frame column): the point o, the line (o, z), the plane through o with normal axis i,
# the free axis i.
_CHARACTERISTIC: dict[Kind, tuple[tuple[int, int], ...]] = {
    Kind.FIXED: ((_POINT, 3), (_LINE, 2), (_PLANE, 0)),
    Kind.REVOLUTE: ((_POINT, 3), (_LINE, 2)),
    Kind.PRISMATIC: ((_LINE, 2), (_PLANE, 0)),
    Kind.CYLINDRICAL: ((_LINE, 2),),
    Kind.TRANSLATION2: ((_PLANE, 2), (_DIRECTION, 0)),
    Kind.TRANSLATION3: ((_DIRECTION, 0), (_DIRECTION, 1)),
    Kind.SPHERICAL: ((_POINT, 3),),
    Kind.PLANAR: ((_PLANE, 2),),
    Kind.SCHOENFLIES: ((_DIRECTION, 2),),
    Kind.FREE: (),
}


def characteristic_flats(kind: Kind, frame: NDArray[np.float64]) -> tuple[_Flat, ...]:
    """The characteristic invariants of the connected TR group of ``kind`` placed by
    ``frame`` (§2.4) as float tuples (type code, point, direction)."""
    items = _CHARACTERISTIC.get(kind)
    if items is None:
        raise FeatureError(
            f"a {kind.value} group has no characteristic invariants (not a TR group)"
        )
    columns = tuple(map(tuple, frame[:3].T.tolist()))
    o = columns[3]
    return tuple(
        (code, None if code == _DIRECTION else o, None if code == _POINT else columns[i])
        for code, i in items
    )


def move_flats(
    t: NDArray[np.float64], flats: tuple[_Flat, ...], inverse: bool = False
) -> tuple[_Flat, ...]:
    """Float invariants moved by the rigid transform ``t`` (by t^-1 when ``inverse``)."""
    (a, b, c, x), (d, e, f, y), (g, h, i, z) = t[:3].tolist()
    if inverse:
        # (R, t)^-1 = (R^T, -R^T t)
        a, b, c, d, e, f, g, h, i = a, d, g, b, e, h, c, f, i
        x, y, z = -(a * x + b * y + c * z), -(d * x + e * y + f * z), -(g * x + h * y + i * z)
    out: list[_Flat] = []
    for code, p, u in flats:
        if p is not None:
            p0, p1, p2 = p
            p = (
                a * p0 + b * p1 + c * p2 + x,
                d * p0 + e * p1 + f * p2 + y,
                g * p0 + h * p1 + i * p2 + z,
            )
        if u is not None:
            u0, u1, u2 = u
            u = (a * u0 + b * u1 + c * u2, d * u0 + e * u1 + f * u2, g * u0 + h * u1 + i * u2)
        out.append((code, p, u))
    return tuple(out)


def _unflatten(flat: _Flat) -> Invariant:
    """The invariant object of a float invariant (known finite and normalised)."""
    code, p, u = flat
    fields: dict[str, Any] = {"_flat": flat}
    if p is not None:
        fields["point"] = np.array(p)
    if code == _LINE:
        fields.update(direction=np.array(u), directed=True)
    elif code == _PLANE:
        fields["normal"] = np.array(u)
    elif code == _DIRECTION:
        fields["direction"] = np.array(u)
    cls: type[Invariant] = (PointInvariant, LineInvariant, PlaneInvariant, DirectionInvariant)[code]
    inv: Invariant = object.__new__(cls)
    inv.__dict__.update(fields)  # frozen fields filled directly: the data is trusted
    return inv


def frame_invariants(kind: Kind, frame: NDArray[np.float64]) -> tuple[Invariant, ...]:
    """The characteristic invariants of the connected TR group of ``kind`` placed by
    ``frame`` (§2.4)."""
    return tuple(_unflatten(f) for f in characteristic_flats(kind, frame))


@functools.lru_cache(maxsize=4096)
def characteristic_invariants(group: SymmetryGroup) -> tuple[Invariant, ...]:
    """A tuple of invariants whose directed stabiliser is the connected TR group (§2.4).

    Cached per (immutable) group: every coset intersection asks for it.
    """
    return frame_invariants(group.kind, group.frame)


# ----------------------------------------------------------------------------- transporter


_Rows = tuple[Vec3, Vec3, Vec3]
_IDENTITY_ROWS: _Rows = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))


def _miss(
    rot: _Rows, shift: Vec3, source: _Flat, target: _Flat, angle: float, length: float
) -> float:
    """How far ``x . source`` is from ``target`` for x = (rot, shift) (0 when it
    coincides): max of the angular error over ``angle`` and the length error over
    ``length`` (the tolerances)."""
    (a0, a1, a2), (b0, b1, b2), (c0, c1, c2) = rot
    code, p, u = source
    _, tp, tu = target
    err_a = err_l = 0.0
    if u is not None:
        assert tu is not None
        m0 = a0 * u[0] + a1 * u[1] + a2 * u[2]
        m1 = b0 * u[0] + b1 * u[1] + b2 * u[2]
        m2 = c0 * u[0] + c1 * u[1] + c2 * u[2]
        err_a = math.sqrt((m0 - tu[0]) ** 2 + (m1 - tu[1]) ** 2 + (m2 - tu[2]) ** 2)
    if p is not None:
        assert tp is not None
        d0 = a0 * p[0] + a1 * p[1] + a2 * p[2] + shift[0] - tp[0]
        d1 = b0 * p[0] + b1 * p[1] + b2 * p[2] + shift[1] - tp[1]
        d2 = c0 * p[0] + c1 * p[1] + c2 * p[2] + shift[2] - tp[2]
        if code == _PLANE:
            assert tu is not None
            err_l = abs(tu[0] * d0 + tu[1] * d1 + tu[2] * d2)
        else:
            if code == _LINE:
                assert tu is not None
                along = tu[0] * d0 + tu[1] * d1 + tu[2] * d2
                d0, d1, d2 = d0 - along * tu[0], d1 - along * tu[1], d2 - along * tu[2]
            err_l = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
    return max(err_a / angle, err_l / length)


def _frame_rows(columns: tuple[Vec3, ...]) -> tuple[_Rows, Vec3]:
    """The rotation (as rows) and origin of frame columns; no axes means the identity."""
    if len(columns) == 1:
        return _IDENTITY_ROWS, columns[0]
    (x0, x1, x2), (y0, y1, y2), (z0, z1, z2), origin = columns
    return ((x0, y0, z0), (x1, y1, z1), (x2, y2, z2)), origin


def _relative(target: tuple[Vec3, ...], source: tuple[Vec3, ...]) -> tuple[_Rows, Vec3]:
    """X0 = F_target . F_source^-1 = (R_t R_s^T, o_t - R_t R_s^T o_s) as (rows, translation)."""
    rt, ot = _frame_rows(target)
    ((p0, p1, p2), (q0, q1, q2), (w0, w1, w2)), (s0, s1, s2) = _frame_rows(source)
    rows: list[Vec3] = []
    shift: list[float] = []
    for (x, y, z), o in zip(rt, ot, strict=True):
        r0, r1, r2 = x * p0 + y * p1 + z * p2, x * q0 + y * q1 + z * q2, x * w0 + y * w1 + z * w2
        rows.append((r0, r1, r2))
        shift.append(o - (r0 * s0 + r1 * s1 + r2 * s2))
    return (rows[0], rows[1], rows[2]), (shift[0], shift[1], shift[2])


def flat_transport(
    targets: tuple[_Flat, ...], sources: tuple[_Flat, ...], tol: Tolerance
) -> NDArray[np.float64] | Mismatch:
    """The representative X0 of the transporter of directed float invariants (§2.5
    closed form: X0 = Frame(targets) . Frame(sources)^-1, then every source checked to
    land on its target), or the first failing congruence test when one does not."""
    rot, shift = _relative(_frame_columns(targets, tol), _frame_columns(sources, tol))
    angle, length = tol.angle, tol.length
    worst = 0.0
    for s, t in zip(sources, targets, strict=True):
        worst = max(worst, _miss(rot, shift, s, t, angle, length))
    if worst > 1.0:
        found = congruence_mismatch(
            [_unflatten(f) for f in targets], [_unflatten(f) for f in sources], tol
        )
        if found is None:
            found = Mismatch(
                MismatchKind.HANDEDNESS,
                worst,
                "the invariants are pairwise congruent but not under a proper rigid motion",
            )
        return found
    (r0, r1, r2), (t0, t1, t2) = rot, shift
    return np.array(((*r0, t0), (*r1, t1), (*r2, t2), (0.0, 0.0, 0.0, 1.0)))


def directed_transport(
    targets: tuple[Invariant, ...], sources: tuple[Invariant, ...], tol: Tolerance
) -> tuple[SymmetryGroup, NDArray[np.float64]] | Mismatch:
    """The transporter of directed tuples as (Stab(targets), X0), or the first failing
    congruence test (§2.5)."""
    flat_t = tuple(_flat(i) for i in targets)
    flat_s = tuple(_flat(i) for i in sources)
    stab = directed_stabilizer(targets, tol)
    found = flat_transport(flat_t, flat_s, tol)
    if isinstance(found, Mismatch):
        return found
    return stab, found


def _flip(line: LineInvariant) -> LineInvariant:
    return LineInvariant(line.point, -line.direction, directed=True)


def direction_choices(
    targets: tuple[Invariant, ...], sources: tuple[Invariant, ...]
) -> tuple[tuple[Invariant, ...], list[tuple[Invariant, ...]]] | Mismatch:
    """The targets with every line directed, and one directed source tuple per choice
    of direction of the lines undirected on either side (§2.5: a union over the
    direction choices); a "type" mismatch when the tuples do not correspond."""
    found = _shape_mismatch(targets, sources)
    if found is not None:
        return found
    free = [
        i
        for i, (t, s) in enumerate(zip(targets, sources, strict=True))
        if isinstance(t, LineInvariant)
        and isinstance(s, LineInvariant)
        and not (t.directed and s.directed)
    ]
    directed_t = tuple(_as_directed(t) for t in targets)
    if not free:
        return directed_t, [tuple(_as_directed(s) for s in sources)]
    choices: list[tuple[Invariant, ...]] = []
    for signs in itertools.product((False, True), repeat=len(free)):
        flipped = list(_as_directed(s) for s in sources)
        for i, flip in zip(free, signs, strict=True):
            if flip:
                flipped[i] = _flip(flipped[i])  # type: ignore[arg-type]
        choices.append(tuple(flipped))
    return directed_t, choices


def _as_directed(inv: Invariant) -> Invariant:
    if isinstance(inv, LineInvariant) and not inv.directed:
        return LineInvariant(inv.point, inv.direction, directed=True)
    return inv
