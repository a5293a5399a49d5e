"""Characteristic invariants, their stabilisers and transporters (ALGEBRA.md §2.4-§2.5).

A TR group is the stabiliser of a tuple of geometric objects (points, directed lines,
oriented planes, free directions). A relation between two bodies is the transporter
{X : X . sources[i] = targets[i]} = Stab(targets) . X0, with X0 built from frames made
by the *same* rule on both tuples (§2.5 "Closed form through characteristic invariants").
"""

from __future__ import annotations

import functools
import itertools
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from assemblykit.algebra import se3
from assemblykit.algebra.cosets import Coset, EmptySet, Mismatch
from assemblykit.algebra.subgroups import Kind, SymmetryGroup, _tr_meet, min_norm_solve
from assemblykit.errors import FeatureError
from assemblykit.tolerance import Tolerance, current

__all__ = [
    "DirectionInvariant",
    "Invariant",
    "LineInvariant",
    "PlaneInvariant",
    "PointInvariant",
    "characteristic_invariants",
    "congruence_mismatch",
    "pair_frame",
    "stabilizer",
    "transform_invariant",
    "transporter",
    "tuple_frame",
]


def _vec(v: Any) -> np.ndarray:
    a = np.asarray(v, dtype=np.float64)
    if a.shape != (3,):
        a = a.reshape(3)
    if not (math.isfinite(a[0]) and math.isfinite(a[1]) and math.isfinite(a[2])):
        raise FeatureError(f"non-finite coordinates {a.tolist()}")
    return a


def _direction(v: Any, what: str) -> np.ndarray:
    a = _vec(v)
    if not float(a @ a) > 0.0:
        raise FeatureError(f"zero {what} vector")
    return se3.unit(a)


@dataclass(frozen=True, eq=False)
class PointInvariant:
    """A point (stabiliser S(point))."""

    point: np.ndarray

    def __post_init__(self) -> None:
        object.__setattr__(self, "point", _vec(self.point))


@dataclass(frozen=True, eq=False)
class LineInvariant:
    """A line through ``point`` along ``direction``; directed lines have stabiliser C,
    undirected ones C ⋊ Z2 (a half-turn flip)."""

    point: np.ndarray
    direction: np.ndarray
    directed: bool = True

    def __post_init__(self) -> None:
        object.__setattr__(self, "point", _vec(self.point))
        object.__setattr__(self, "direction", _direction(self.direction, "line direction"))


@dataclass(frozen=True, eq=False)
class PlaneInvariant:
    """An oriented plane through ``point`` with unit ``normal`` (stabiliser G(normal))."""

    point: np.ndarray
    normal: np.ndarray

    def __post_init__(self) -> None:
        object.__setattr__(self, "point", _vec(self.point))
        object.__setattr__(self, "normal", _direction(self.normal, "plane normal"))


@dataclass(frozen=True, eq=False)
class DirectionInvariant:
    """A free unit vector (stabiliser X(direction))."""

    direction: np.ndarray

    def __post_init__(self) -> None:
        object.__setattr__(self, "direction", _direction(self.direction, "direction"))


Invariant = PointInvariant | LineInvariant | PlaneInvariant | DirectionInvariant


def _trusted(cls: type, **fields: Any) -> Any:
    """An invariant from data already known to be finite and normalised (skips checks:
    transformed and characteristic invariants are built in the hot path)."""
    out = object.__new__(cls)
    for name, value in fields.items():
        object.__setattr__(out, name, value)
    return out


def transform_invariant(t: np.ndarray, inv: Invariant) -> Invariant:
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


def _axis_of(inv: Invariant) -> np.ndarray | None:
    if isinstance(inv, LineInvariant | DirectionInvariant):
        return inv.direction
    if isinstance(inv, PlaneInvariant):
        return inv.normal
    return None


# ----------------------------------------------------------------------------- congruence


def _angle(a: np.ndarray, b: np.ndarray) -> float:
    return math.atan2(se3.norm(se3.cross(a, b)), float(a @ b))


def _perp(v: np.ndarray, u: np.ndarray) -> np.ndarray:
    return v - (v @ u) * u


def _pair_measures(a: Invariant, b: Invariant, tol: Tolerance) -> list[tuple[str, float]]:
    """The congruence measures of one pair (§2.5 table, "congruence test" column)."""
    out: list[tuple[str, float]] = []
    ua, ub = _axis_of(a), _axis_of(b)
    if ua is not None and ub is not None:
        out.append(("angle", _angle(ua, ub)))
    if isinstance(b, PointInvariant) and not isinstance(a, PointInvariant):
        a, b = b, a
    if isinstance(a, PointInvariant):
        if isinstance(b, PointInvariant):
            out.append(("distance", se3.norm(b.point - a.point)))
        elif isinstance(b, LineInvariant):
            out.append(("distance", se3.norm(_perp(a.point - b.point, b.direction))))
        elif isinstance(b, PlaneInvariant):
            out.append(("distance", float(b.normal @ (a.point - b.point))))
        return out
    if isinstance(a, PlaneInvariant) and isinstance(b, LineInvariant):
        a, b = b, a
    if isinstance(a, LineInvariant) and isinstance(b, LineInvariant):
        cross = se3.cross(a.direction, b.direction)
        norm = se3.norm(cross)
        offset = b.point - a.point
        if norm <= tol.angle:
            out.append(("distance", se3.norm(_perp(offset, a.direction))))
        else:
            signed = float(cross @ offset) / norm
            out.append(("distance", abs(signed)))
            if a.directed and b.directed:
                out.append(("moment", signed))
    elif isinstance(a, LineInvariant) and isinstance(b, PlaneInvariant):
        if abs(float(a.direction @ b.normal)) <= tol.angle:
            out.append(("distance", float(b.normal @ (a.point - b.point))))
    elif (
        isinstance(a, PlaneInvariant)
        and isinstance(b, PlaneInvariant)
        and se3.norm(se3.cross(a.normal, b.normal)) <= tol.angle
    ):
        out.append(("distance", float(a.normal @ (b.point - a.point))))
    return out


def _describe_mismatch(kind: str, value: float, i: int, j: int) -> Mismatch:
    where = f"between invariants {i} and {j}"
    if kind == "angle":
        text = f"angle mismatch {math.degrees(value):.6g}° {where}"
    elif kind == "moment":
        text = f"moment (handedness) mismatch {value:.6g} {where}"
    else:
        text = f"{kind} mismatch {value:.6g} {where}"
    return Mismatch(kind, value, text)


def _shape_mismatch(targets: Any, sources: Any) -> Mismatch | None:
    """A "type" mismatch when the tuples differ in length or in invariant types."""
    if len(targets) != len(sources):
        return Mismatch("type", float(abs(len(targets) - len(sources))), "different counts")
    for i, (t, s) in enumerate(zip(targets, sources, strict=True)):
        if type(t) is not type(s):
            return Mismatch("type", 1.0, f"invariant {i}: {type(t).__name__} vs {type(s).__name__}")
    return None


def congruence_mismatch(
    targets: tuple[Invariant, ...] | list[Invariant],
    sources: tuple[Invariant, ...] | list[Invariant],
    tol: Tolerance | None = None,
) -> Mismatch | None:
    """The first failing pairwise congruence test (angles, distances, signed moments),
    or ``None`` when every pair agrees (ALGEBRA.md §2.5)."""
    tol = tol or current()
    shape = _shape_mismatch(targets, sources)
    if shape is not None:
        return shape
    for i, j in itertools.combinations(range(len(targets)), 2):
        mt = _pair_measures(targets[i], targets[j], tol)
        ms = _pair_measures(sources[i], sources[j], tol)
        for (kind, vt), (_, vs) in zip(mt, ms, strict=False):
            limit = tol.angle if kind == "angle" else tol.length
            if abs(vt - vs) > limit:
                return _describe_mismatch(kind, abs(vt - vs), i, j)
        if len(mt) != len(ms):
            return _describe_mismatch("angle", 0.0, i, j)
    return None


# ----------------------------------------------------------------------------- frames


def tuple_frame(invariants: tuple[Invariant, ...] | list[Invariant], tol: Tolerance | None = None):
    """A frame built from the tuple by a rule that commutes with rigid motions up to the
    tuple's stabiliser (§2.5: "the same rule on both sides").

    Origin: the least-squares point nearest to all points, lines and planes (minimum
    norm along the directions every object contains). Axes: the first intrinsic
    direction (line, normal, free direction) or offset from the origin to an object is
    +z; the first one not parallel to it fixes +x.
    """
    tol = tol or current()
    m = np.zeros((3, 3))
    rhs = np.zeros(3)
    for inv in invariants:
        p = _projector(inv)
        if p is not None:
            m += p
            rhs += p @ _anchor(inv)
    origin = min_norm_solve(m, rhs, tol)
    dirs = [d for d in (_axis_of(inv) for inv in invariants) if d is not None]
    for inv in invariants:
        p = _projector(inv)
        if p is not None:
            off = p @ (_anchor(inv) - origin)
            if se3.norm(off) > tol.length:
                dirs.append(se3.unit(off))
    if not dirs:
        return se3.translation(origin)
    z = dirs[0]
    hint = next((d for d in dirs[1:] if se3.norm(se3.cross(z, d)) > tol.angle), None)
    return se3.frame(origin, z, hint)


def _projector(inv: Invariant) -> np.ndarray | None:
    """Projector onto the normal space of the object's affine set (None for directions)."""
    if isinstance(inv, PointInvariant):
        return np.eye(3)
    if isinstance(inv, LineInvariant):
        return np.eye(3) - np.outer(inv.direction, inv.direction)
    if isinstance(inv, PlaneInvariant):
        return np.outer(inv.normal, inv.normal)
    return None


def _anchor(inv: Invariant) -> np.ndarray:
    assert not isinstance(inv, DirectionInvariant)
    return inv.point


def pair_frame(first: Invariant, second: Invariant, tol: Tolerance | None = None) -> np.ndarray:
    """The §2.5 pair frame of two invariants (``tuple_frame`` of the pair)."""
    return tuple_frame((first, second), tol)


# ----------------------------------------------------------------------------- stabilisers


def _single_stabilizer(inv: Invariant) -> SymmetryGroup:
    if isinstance(inv, PointInvariant):
        return SymmetryGroup.spherical(inv.point)
    if isinstance(inv, LineInvariant):
        return SymmetryGroup.cylindrical(inv.point, inv.direction)
    if isinstance(inv, PlaneInvariant):
        return SymmetryGroup(Kind.PLANAR, se3.frame(inv.point, inv.normal))
    return SymmetryGroup.schoenflies(inv.direction)


def _directed_stabilizer(invariants: tuple[Invariant, ...], tol: Tolerance) -> SymmetryGroup:
    """Stab of the tuple with every line taken as directed: the meet of the TR stabilisers."""
    if not invariants:
        return SymmetryGroup.free()
    group = _single_stabilizer(invariants[0])
    for inv in invariants[1:]:
        group = _tr_meet(group, _single_stabilizer(inv), tol)
    return group


def stabilizer(
    invariants: tuple[Invariant, ...] | list[Invariant], tol: Tolerance | None = None
) -> SymmetryGroup:
    """The group fixing every invariant; undirected lines contribute flips (§2.4)."""
    tol = tol or current()
    invs = tuple(invariants)
    if all(not isinstance(i, LineInvariant) or i.directed for i in invs):
        return _directed_stabilizer(invs, tol)
    result = transporter(invs, invs, tol)
    assert isinstance(result, Coset)
    return result.group


@functools.lru_cache(maxsize=4096)
def characteristic_invariants(group: SymmetryGroup) -> tuple[Invariant, ...]:
    """A tuple of invariants whose directed stabiliser is the connected TR group (§2.4).

    Cached per (immutable) group: every coset intersection asks for it.
    """
    k, f = group.kind.value, group.frame
    o, x, y, z = f[:3, 3], f[:3, 0], f[:3, 1], f[:3, 2]
    point = _trusted(PointInvariant, point=o)
    axis = _trusted(LineInvariant, point=o, direction=z, directed=True)
    table: dict[str, tuple[Invariant, ...]] = {
        "fixed": (point, axis, _trusted(PlaneInvariant, point=o, normal=x)),
        "revolute": (point, axis),
        "prismatic": (axis, _trusted(PlaneInvariant, point=o, normal=x)),
        "cylindrical": (axis,),
        "translation2": (
            _trusted(PlaneInvariant, point=o, normal=z),
            _trusted(DirectionInvariant, direction=x),
        ),
        "translation3": (
            _trusted(DirectionInvariant, direction=x),
            _trusted(DirectionInvariant, direction=y),
        ),
        "spherical": (point,),
        "planar": (_trusted(PlaneInvariant, point=o, normal=z),),
        "schoenflies": (_trusted(DirectionInvariant, direction=z),),
        "free": (),
    }
    if k not in table:
        raise FeatureError(f"a {k} group has no characteristic invariants (not a TR group)")
    return table[k]


# ----------------------------------------------------------------------------- transporter


def _maps_onto(x: np.ndarray, source: Invariant, target: Invariant, tol: Tolerance) -> float:
    """How far ``x . source`` is from ``target`` (0 when it coincides): max of the
    angular error and the length error divided by the scale."""
    moved = transform_invariant(x, source)
    err_a, err_l = 0.0, 0.0
    if isinstance(moved, PointInvariant):
        assert isinstance(target, PointInvariant)
        err_l = se3.norm(moved.point - target.point)
    elif isinstance(moved, LineInvariant):
        assert isinstance(target, LineInvariant)
        err_a = se3.norm(moved.direction - target.direction)
        err_l = se3.norm(_perp(moved.point - target.point, target.direction))
    elif isinstance(moved, PlaneInvariant):
        assert isinstance(target, PlaneInvariant)
        err_a = se3.norm(moved.normal - target.normal)
        err_l = abs(float(target.normal @ (moved.point - target.point)))
    else:
        assert isinstance(target, DirectionInvariant)
        err_a = se3.norm(moved.direction - target.direction)
    return max(err_a / tol.angle, err_l / tol.length)


def _directed_transporter(
    targets: tuple[Invariant, ...],
    sources: tuple[Invariant, ...],
    tol: Tolerance,
    group: SymmetryGroup | None = None,
) -> Coset | EmptySet:
    """The transporter of directed tuples; ``group`` is Stab(targets) when already known."""
    x0 = tuple_frame(targets, tol) @ se3.inverse(tuple_frame(sources, tol))
    worst = max(
        (_maps_onto(x0, s, t, tol) for s, t in zip(sources, targets, strict=True)), default=0
    )
    if worst > 1.0:
        found = congruence_mismatch(targets, sources, tol)
        if found is None:
            found = Mismatch(
                "handedness",
                worst,
                "the invariants are pairwise congruent but not under a proper rigid motion",
            )
        return EmptySet(found)
    return Coset(group if group is not None else _directed_stabilizer(targets, tol), x0)


def _flip(line: LineInvariant) -> LineInvariant:
    return LineInvariant(line.point, -line.direction, directed=True)


def transporter(
    targets: tuple[Invariant, ...] | list[Invariant],
    sources: tuple[Invariant, ...] | list[Invariant],
    tol: Tolerance | None = None,
) -> Coset | EmptySet:
    """{X in SE(3) : X . sources[i] = targets[i] for all i} (ALGEBRA.md §2.5).

    ``targets`` are in body-1 coordinates, ``sources`` in body-2 coordinates. Empty when
    the tuples are not congruent (the first failing test is reported); undirected lines
    give a union over the direction choices, i.e. extra components.
    """
    tol = tol or current()
    tgt, src = tuple(targets), tuple(sources)
    found = _shape_mismatch(tgt, src)
    if found is not None:
        return EmptySet(found)
    free = [
        i
        for i, (t, s) in enumerate(zip(tgt, src, strict=True))
        if isinstance(t, LineInvariant)
        and isinstance(s, LineInvariant)
        and not (t.directed and s.directed)
    ]
    directed_t = tuple(_as_directed(t) for t in tgt)
    if not free:
        return _directed_transporter(directed_t, tuple(_as_directed(s) for s in src), tol)
    results: list[Coset | EmptySet] = []
    for signs in itertools.product((False, True), repeat=len(free)):
        flipped = list(_as_directed(s) for s in src)
        for i, flip in zip(free, signs, strict=True):
            if flip:
                flipped[i] = _flip(flipped[i])  # type: ignore[arg-type]
        results.append(_directed_transporter(directed_t, tuple(flipped), tol))
    cosets = [r for r in results if isinstance(r, Coset)]
    if not cosets:
        return results[0]
    base = cosets[0]
    reps = tuple(c.rep @ se3.inverse(base.rep) for c in cosets[1:])
    return Coset(base.group.with_discrete(reps=reps, tol=tol), base.rep)


def _as_directed(inv: Invariant) -> Invariant:
    if isinstance(inv, LineInvariant) and not inv.directed:
        return LineInvariant(inv.point, inv.direction, directed=True)
    return inv
