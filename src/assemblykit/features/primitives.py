"""Oriented primitive features and their symmetry groups (Liu 1997 §2, docs/algebra.md §4).

A feature is an oriented surface of a body (Liu 1997 Def. 2.1.2: the surface plus its
outward normals), or an auxiliary datum (point, axis, frame). Every feature has

* a **frame** F in its body (DESIGN §4): origin on the feature, +z along the outward
  normal (planes) or the axis (shafts root→tip, holes opening→inside, cones and threads
  and prisms along their axis);
* a **symmetry group** ``group()`` = F·Sym·F⁻¹ in body coordinates, Sym the canonical
  group of docs/algebra.md §4's table (directed or undirected);
* **characteristic invariants** (docs/algebra.md §2.4) used by transporters.

The keyword arguments are exactly the keys of the task file (DESIGN §5.1), so
``feature_from_dict`` is a thin schema layer over the constructors.
"""

from __future__ import annotations

import functools
import math
import re
from abc import ABC, abstractmethod
from collections.abc import Callable, Mapping
from dataclasses import MISSING, dataclass, fields, replace
from typing import Any, ClassVar, Self

import numpy as np
from numpy.typing import NDArray

from assemblykit.algebra import (
    DirectionInvariant,
    Invariant,
    Kind,
    LineInvariant,
    PlaneInvariant,
    PointInvariant,
    SymmetryGroup,
    se3,
)
from assemblykit.errors import FeatureError, SchemaError
from assemblykit.tolerance import MAX_MAGNITUDE

Vector = NDArray[np.float64]
Matrix = NDArray[np.float64]

_ANGLE = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(deg|rad)?\s*$")


def is_angle_text(text: str) -> bool:
    """Whether ``text`` is an angle written with its unit, such as ``"30 deg"`` or
    ``"0.5 rad"``."""
    match = _ANGLE.match(text)
    return match is not None and match.group(2) is not None


def parse_angle(value: Any, where: str | None = None) -> float:
    """An angle in radians from a number (radians) or a string such as ``"30 deg"``
    (DESIGN §4: degrees are allowed in files when written with ``deg``)."""
    if isinstance(value, bool):
        raise SchemaError(f"expected an angle, got {value!r}", where=where)
    if isinstance(value, int | float):
        angle = float(value)
    elif isinstance(value, str) and (match := _ANGLE.match(value)):
        angle = float(match.group(1))
        if match.group(2) == "deg":
            angle = math.radians(angle)
    else:
        raise SchemaError(f"expected an angle such as 0.5 or '30 deg', got {value!r}", where=where)
    if not math.isfinite(angle):
        raise SchemaError(f"angle must be finite, got {value!r}", where=where)
    return angle


def _frozen(array: NDArray[np.float64]) -> NDArray[np.float64]:
    array.setflags(write=False)
    return array


def _is_number(value: Any) -> bool:
    """Whether ``value`` is a real number (``true`` in a file is not the number 1)."""
    if type(value) in (int, float):
        return True
    return isinstance(value, int | float | np.floating | np.integer) and not isinstance(
        value, bool | np.bool_
    )


def _vector(value: Any, field: str, owner: str) -> Vector:
    """Three finite numbers of magnitude at most ``MAX_MAGNITUDE``: a flat list from a
    file, or any array of three numbers from code."""
    if type(value) is list and len(value) == 3 and all(type(v) in (int, float) for v in value):
        items, numeric = value, True  # the common case: three numbers read from a file
    elif isinstance(value, np.ndarray):
        numeric = value.size == 3 and value.dtype.kind in "iuf"
        items = value.reshape(-1).tolist() if numeric else []
    else:
        items = list(value) if isinstance(value, list | tuple) else []
        numeric = len(items) == 3 and all(_is_number(v) for v in items)
    if not numeric:
        raise FeatureError(f"{field} must be 3 numbers, got {value!r}", where=owner)
    numbers = [float(v) for v in items]
    if not all(map(math.isfinite, numbers)):
        raise FeatureError(f"{field} must be finite, got {numbers}", where=owner)
    if max(map(abs, numbers)) > MAX_MAGNITUDE:
        raise FeatureError(
            f"{field} must be at most {MAX_MAGNITUDE:g} in size, got {numbers}", where=owner
        )
    return _frozen(np.array(numbers, dtype=np.float64))


def _direction(value: Any, field: str, owner: str) -> Vector:
    vec = _vector(value, field, owner)
    norm = math.hypot(*vec.tolist())
    if not norm > 0:
        raise FeatureError(f"{field} must be a non-zero vector", where=owner)
    return _frozen(vec / norm)


def _positive(value: Any, field: str, owner: str) -> float:
    if not _is_number(value):
        raise FeatureError(f"{field} must be a number, got {value!r}", where=owner)
    number = float(value)
    if not (math.isfinite(number) and number > 0):
        raise FeatureError(f"{field} must be a positive number, got {value!r}", where=owner)
    if number > MAX_MAGNITUDE:
        raise FeatureError(f"{field} must be at most {MAX_MAGNITUDE:g}, got {value!r}", where=owner)
    return number


def _flag(value: Any, field: str, owner: str) -> bool:
    if not isinstance(value, bool | np.bool_):
        raise FeatureError(f"{field} must be true or false, got {value!r}", where=owner)
    return bool(value)


def _flip(frame: Matrix) -> Matrix:
    """The half-turn about the frame's x axis, in body coordinates (docs/algebra.md §2.2)."""
    return frame @ se3.rot_x(math.pi) @ se3.inverse(frame)


def _about_axis(frame: Matrix, angle: float) -> Matrix:
    """The rotation by ``angle`` about the frame's z axis, in body coordinates."""
    return frame @ se3.rot_z(angle) @ se3.inverse(frame)


class Feature(ABC):
    """An oriented primitive feature (Liu 1997 Def. 2.1.2) of a body."""

    type_name: ClassVar[str]
    name: str | None

    @property
    def label(self) -> str:
        """The feature's name, or its type when unnamed (used in error messages)."""
        return self.name or self.type_name

    def _validate(self, check: Callable[[Any, str, str], Any], *names: str) -> None:
        """Replace each named field by ``check(value, name, label)``, in order (the frozen
        dataclass is still being built, hence ``object.__setattr__``)."""
        for field_name in names:
            object.__setattr__(
                self, field_name, check(getattr(self, field_name), field_name, self.label)
            )

    @abstractmethod
    def frame(self) -> Matrix:
        """The 4x4 feature frame in body coordinates (DESIGN §4)."""

    @abstractmethod
    def group(self) -> SymmetryGroup:
        """The symmetry group F·Sym·F⁻¹ in body coordinates (docs/algebra.md §4)."""

    @abstractmethod
    def invariants(self) -> tuple[Invariant, ...]:
        """Characteristic invariants whose stabiliser is the connected part of ``group()``."""

    @abstractmethod
    def transformed(self, transform: Matrix) -> Self:
        """The same feature moved by the rigid motion ``transform``."""

    def to_dict(self) -> dict[str, Any]:
        """The task-file mapping of the feature (DESIGN §5.1), without its name."""
        out: dict[str, Any] = {"type": self.type_name}
        for item in fields(self):  # type: ignore[arg-type]
            if item.name == "name":
                continue
            value = getattr(self, item.name)
            if value is None:
                continue
            out[item.name] = value.tolist() if isinstance(value, np.ndarray) else value
        return out


@dataclass(frozen=True, eq=False)
class _Axial(Feature):
    """Shared behaviour of the features carried by an axis line (``point``, ``axis``)."""

    point: Vector
    axis: Vector

    def __post_init__(self) -> None:
        self._validate(_vector, "point")
        self._validate(_direction, "axis")

    def frame(self) -> Matrix:
        return se3.frame(self.point, self.axis)

    def _moved(self, transform: Matrix, **changes: Any) -> dict[str, Any]:
        return {
            "point": se3.apply(transform, self.point),
            "axis": se3.apply_direction(transform, self.axis),
            **changes,
        }

    def transformed(self, transform: Matrix) -> Self:
        return replace(self, **self._moved(transform))


class _Line(_Axial):
    """Shared behaviour of the axial features with a ``directed`` flag: the axis line is
    their invariant, and the half-turn about the frame's x axis joins their group when
    undirected (docs/algebra.md §4). By default the group is the line's own, C(z)."""

    directed: bool

    def _flipped_unless_directed(self, base: SymmetryGroup) -> SymmetryGroup:
        return base if self.directed else base.with_discrete(reps=(_flip(self.frame()),))

    def group(self) -> SymmetryGroup:
        return self._flipped_unless_directed(SymmetryGroup.cylindrical(self.point, self.axis))

    def invariants(self) -> tuple[Invariant, ...]:
        return (LineInvariant(self.point, self.axis, directed=self.directed),)


@dataclass(frozen=True, eq=False)
class Plane(Feature):
    """A planar face through ``point`` with outward unit ``normal``: Sym = G(z), 3 dof.

    The flip is excluded: it would invert the normal (Liu 1997 §2, docs/algebra.md §4)."""

    point: Vector
    normal: Vector
    name: str | None = None
    type_name: ClassVar[str] = "plane"

    def __post_init__(self) -> None:
        self._validate(_vector, "point")
        self._validate(_direction, "normal")

    def frame(self) -> Matrix:
        return se3.frame(self.point, self.normal)

    def group(self) -> SymmetryGroup:
        return SymmetryGroup.planar(self.normal)

    def invariants(self) -> tuple[Invariant, ...]:
        return (PlaneInvariant(self.point, self.normal),)

    def transformed(self, transform: Matrix) -> Plane:
        return replace(
            self,
            point=se3.apply(transform, self.point),
            normal=se3.apply_direction(transform, self.normal),
        )


@dataclass(frozen=True, eq=False)
class _Cylinder(_Line):
    """A cylinder of ``radius`` about the axis line: Sym = C(z), or C(z)⋊⟨Rx(π)⟩ undirected."""

    radius: float
    directed: bool = True
    name: str | None = None

    def __post_init__(self) -> None:
        super().__post_init__()
        self._validate(_positive, "radius")
        self._validate(_flag, "directed")


@dataclass(frozen=True, eq=False)
class Shaft(_Cylinder):
    """A cylindrical shaft (outward normals); ``axis`` points root→tip (DESIGN §4)."""

    type_name: ClassVar[str] = "shaft"


@dataclass(frozen=True, eq=False)
class Hole(_Cylinder):
    """A cylindrical hole (inward normals); ``axis`` points opening→inside (DESIGN §4)."""

    type_name: ClassVar[str] = "hole"


@dataclass(frozen=True, eq=False)
class _Centred(Feature):
    """Shared behaviour of the features centred at ``point``: Sym = S(point), 3 dof."""

    point: Vector

    def __post_init__(self) -> None:
        self._validate(_vector, "point")

    def frame(self) -> Matrix:
        return se3.translation(self.point)

    def group(self) -> SymmetryGroup:
        return SymmetryGroup.spherical(self.point)

    def invariants(self) -> tuple[Invariant, ...]:
        return (PointInvariant(self.point),)

    def transformed(self, transform: Matrix) -> Self:
        return replace(self, point=se3.apply(transform, self.point))


@dataclass(frozen=True, eq=False)
class _Sphere(_Centred):
    """A sphere of ``radius`` about ``point``: Sym = S(point), 3 dof."""

    radius: float
    name: str | None = None

    def __post_init__(self) -> None:
        super().__post_init__()
        self._validate(_positive, "radius")


@dataclass(frozen=True, eq=False)
class Ball(_Sphere):
    """A spherical ball (outward normals) centred at ``point``."""

    type_name: ClassVar[str] = "ball"


@dataclass(frozen=True, eq=False)
class Socket(_Sphere):
    """A spherical socket (inward normals) centred at ``point``."""

    type_name: ClassVar[str] = "socket"


@dataclass(frozen=True, eq=False)
class Cone(_Axial):
    """A single-nappe cone, apex at ``point``, opening along ``axis``: Sym = R(z).

    No flip: it would map the nappe onto the other one (docs/algebra.md §4)."""

    half_angle: float
    male: bool = True
    name: str | None = None
    type_name: ClassVar[str] = "cone"

    def __post_init__(self) -> None:
        super().__post_init__()
        angle = _positive(self.half_angle, "half_angle", self.label)
        if not angle < math.pi / 2:
            raise FeatureError(
                f"half_angle must lie in (0, π/2), got {self.half_angle!r}", where=self.label
            )
        object.__setattr__(self, "half_angle", angle)
        self._validate(_flag, "male")

    def group(self) -> SymmetryGroup:
        return SymmetryGroup.revolute(self.point, self.axis)

    def invariants(self) -> tuple[Invariant, ...]:
        return (LineInvariant(self.point, self.axis, directed=True), PointInvariant(self.point))


@dataclass(frozen=True, eq=False)
class Torus(_Axial):
    """A torus centred at ``point`` about ``axis``: Sym = R(z)⋊⟨Rx(π)⟩ (docs/algebra.md §4).

    The surface is symmetric under the half-turn across its mid-plane, so it is undirected."""

    major_radius: float
    minor_radius: float
    male: bool = True
    name: str | None = None
    type_name: ClassVar[str] = "torus"

    def __post_init__(self) -> None:
        super().__post_init__()
        self._validate(_positive, "major_radius", "minor_radius")
        self._validate(_flag, "male")

    def group(self) -> SymmetryGroup:
        base = SymmetryGroup.revolute(self.point, self.axis)
        return base.with_discrete(reps=(_flip(self.frame()),))

    def invariants(self) -> tuple[Invariant, ...]:
        return (LineInvariant(self.point, self.axis, directed=False), PointInvariant(self.point))


def _phase_after(frame: Matrix, transform: Matrix) -> float:
    """The angle of the moved frame's x axis about its z axis, measured from the x axis of
    the default frame at the moved origin and axis (so ``transformed`` commutes with
    ``frame``)."""
    moved = transform @ frame
    default = se3.frame(moved[:3, 3], moved[:3, 2])
    x = moved[:3, 0]
    return math.atan2(float(x @ default[:3, 1]), float(x @ default[:3, 0]))


@dataclass(frozen=True, eq=False)
class Thread(_Line):
    """A helical thread of ``radius`` and ``lead`` (axial advance per turn) about the axis.

    Sym = H(z, p) with pitch p = ±lead/2π (+ for a right hand, docs/algebra.md §1 and §7), or
    H(z, p)⋊⟨Rx(π)⟩ undirected. ``phase`` is the angle of the thread start about the axis
    from the default frame's x axis; the frame's x axis points at the thread start, so the
    flip axis of an undirected thread is that perpendicular (docs/algebra.md §4). The helical
    part is not a TR invariant (docs/algebra.md §2.4): the invariant is the axis line alone."""

    radius: float
    lead: float
    hand: str = "right"
    male: bool = True
    phase: float = 0.0
    directed: bool = True
    name: str | None = None
    type_name: ClassVar[str] = "thread"

    def __post_init__(self) -> None:
        super().__post_init__()
        self._validate(_positive, "radius", "lead")
        if self.hand not in ("right", "left"):
            raise FeatureError(
                f"hand must be 'right' or 'left', got {self.hand!r}", where=self.label
            )
        self._validate(_flag, "male", "directed")
        phase = parse_angle(self.phase, self.label)
        object.__setattr__(self, "phase", math.remainder(phase, 2 * math.pi))

    @property
    def pitch(self) -> float:
        """The signed pitch p (translation per radian), positive for a right hand."""
        sign = 1.0 if self.hand == "right" else -1.0
        return sign * self.lead / (2 * math.pi)

    def frame(self) -> Matrix:
        return se3.frame(self.point, self.axis) @ se3.rot_z(self.phase)

    def group(self) -> SymmetryGroup:
        base = SymmetryGroup.helical(self.point, self.axis, self.pitch)
        return self._flipped_unless_directed(base)

    def transformed(self, transform: Matrix) -> Thread:
        return replace(self, **self._moved(transform, phase=_phase_after(self.frame(), transform)))


@dataclass(frozen=True, eq=False)
class Prism(_Line):
    """A prism of regular ``sides``-gon section along the axis (a spline, a square peg).

    ``size`` is the circumradius (axis to vertex) and ``ref`` the direction from the axis
    to one vertex (default: the default frame's x axis). Sym = T(z)⋊Cₙ, or T(z)⋊Dₙ
    undirected, the extra half-turns being about the vertex and mid-edge directions
    (docs/algebra.md §4)."""

    sides: int
    size: float
    male: bool = True
    directed: bool = True
    ref: Vector | None = None
    name: str | None = None
    type_name: ClassVar[str] = "prism"

    def __post_init__(self) -> None:
        super().__post_init__()
        if isinstance(self.sides, bool) or not isinstance(self.sides, int | np.integer):
            raise FeatureError(f"sides must be an integer, got {self.sides!r}", where=self.label)
        if self.sides < 2:
            raise FeatureError(f"sides must be at least 2, got {self.sides}", where=self.label)
        object.__setattr__(self, "sides", int(self.sides))
        self._validate(_positive, "size")
        self._validate(_flag, "male", "directed")
        if self.ref is not None:
            ref = _vector(self.ref, "ref", self.label)
            across = ref - (ref @ self.axis) * self.axis
            norm = float(np.linalg.norm(across))
            if not norm > 0:
                raise FeatureError("ref must not be parallel to the axis", where=self.label)
            object.__setattr__(self, "ref", _frozen(across / norm))

    def frame(self) -> Matrix:
        return se3.frame(self.point, self.axis, self.ref)

    def group(self) -> SymmetryGroup:
        frame = self.frame()
        turns = [_about_axis(frame, 2 * math.pi * k / self.sides) for k in range(1, self.sides)]
        if not self.directed:
            flip = _flip(frame)
            turns += [flip] + [turn @ flip for turn in turns]
        # The transversal is known in closed form: no closure search needed.
        return SymmetryGroup(Kind.PRISMATIC, frame, 0.0, (np.eye(4), *turns))

    def transformed(self, transform: Matrix) -> Prism:
        ref = se3.apply_direction(transform, self.frame()[:3, 0])
        return replace(self, **self._moved(transform, ref=ref))


@dataclass(frozen=True, eq=False)
class Point(_Centred):
    """A datum point: Sym = S(point)."""

    name: str | None = None
    type_name: ClassVar[str] = "point"


@dataclass(frozen=True, eq=False)
class Axis(_Line):
    """A datum line: Sym = C(z), or C(z)⋊⟨Rx(π)⟩ undirected."""

    directed: bool = True
    name: str | None = None
    type_name: ClassVar[str] = "axis"

    def __post_init__(self) -> None:
        super().__post_init__()
        self._validate(_flag, "directed")


@dataclass(frozen=True, eq=False)
class Frame(Feature):
    """A datum frame given by its 4x4 ``matrix`` (a proper rigid motion): Sym = {I}."""

    matrix: Matrix
    name: str | None = None
    type_name: ClassVar[str] = "frame"

    def __post_init__(self) -> None:
        try:
            matrix = np.array(self.matrix, dtype=np.float64)
        except (TypeError, ValueError):
            raise FeatureError("matrix must be 4x4 numbers", where=self.label) from None
        if matrix.shape != (4, 4) or not np.all(np.isfinite(matrix)):
            raise FeatureError("matrix must be 4x4 finite numbers", where=self.label)
        if not se3.is_rigid(matrix):
            raise FeatureError("matrix must be a proper rigid motion", where=self.label)
        object.__setattr__(self, "matrix", _frozen(matrix))

    def frame(self) -> Matrix:
        return self.matrix.copy()

    def group(self) -> SymmetryGroup:
        return SymmetryGroup.identity()

    def invariants(self) -> tuple[Invariant, ...]:
        origin = self.matrix[:3, 3]
        return (
            PointInvariant(origin),
            DirectionInvariant(self.matrix[:3, 2]),
            DirectionInvariant(self.matrix[:3, 0]),
        )

    def transformed(self, transform: Matrix) -> Frame:
        return replace(self, matrix=transform @ self.matrix)


FEATURE_TYPES: Mapping[str, type[Feature]] = {
    cls.type_name: cls
    for cls in (Plane, Shaft, Hole, Ball, Socket, Cone, Torus, Thread, Prism, Point, Axis, Frame)
}

_ANGLE_KEYS = frozenset({"half_angle", "phase"})


@functools.cache
def _keys(cls: type[Feature]) -> tuple[frozenset[str], frozenset[str]]:
    """The keys a task file may give a feature of type ``cls``, and those it must."""
    named = [f for f in fields(cls) if f.name != "name"]  # type: ignore[arg-type]
    required = (f.name for f in named if f.default is MISSING and f.default_factory is MISSING)
    return frozenset(f.name for f in named), frozenset(required)


def feature_from_dict(name: str, data: Mapping[str, Any], where: str | None = None) -> Feature:
    """Build a feature from its task-file mapping (DESIGN §5.1), e.g.
    ``{type: plane, point: [0, 0, 0], normal: [0, 0, 1]}``.

    Angles (``half_angle``, ``phase``) are radians or strings such as ``"30 deg"``.
    Raises :class:`SchemaError` for a missing/unknown type or key and
    :class:`FeatureError` for invalid values, both naming ``where`` (default: ``name``).
    """
    where = where or name
    if not isinstance(data, Mapping):
        raise SchemaError(f"a feature must be a mapping, got {data!r}", where=where)
    kind = data.get("type")
    if not isinstance(kind, str) or kind not in FEATURE_TYPES:
        known = ", ".join(FEATURE_TYPES)
        raise SchemaError(f"unknown feature type {kind!r} (expected one of {known})", where=where)
    cls = FEATURE_TYPES[kind]
    allowed, required = _keys(cls)
    values = {key: value for key, value in data.items() if key != "type"}
    if unknown := sorted(set(values) - allowed):
        raise SchemaError(
            f"unknown key(s) {', '.join(map(str, unknown))} for a {kind} "
            f"(allowed: {', '.join(sorted(allowed))})",
            where=where,
        )
    if missing := sorted(required - set(values)):
        raise SchemaError(f"a {kind} needs {', '.join(missing)}", where=where)
    for key in _ANGLE_KEYS & set(values):
        values[key] = parse_angle(values[key], f"{where}.{key}")
    build: Callable[..., Feature] = cls  # each subclass's own fields, checked above
    try:
        return build(name=name, **values)
    except FeatureError as error:
        raise FeatureError(error.detail, where=where) from None
