"""The relation vocabulary: one class per relation kind, registered in one table.

A relation ``[kind, first, second, {options}]`` between features of two bodies constrains
X = L₂⁻¹·L₁, the pose of the *first* feature's body in the frame of the *second*
feature's body (docs/algebra.md §5.1: the second feature's body is body 1, the "from" side).
So ``[against, block.bottom, table.top]`` is the set of block poses in the table frame.

Each kind is a subclass of :class:`RelationType` that holds all the kind means: its
arity, the feature pairs and options it accepts, its coset, its residual, the dof it
removes, whether it couples motions through a third body, and the closed-form geometry
of the higher pairs. :data:`RELATIONS` maps every kind's name to its class's instance;
:func:`register_relation` adds a kind, as ``FEATURE_TYPES`` lists the feature classes.
A task's relations keep the kind's name (the task file of docs/tutorial.md §1) and look the
class up in the table.

Lower-pair relations are right cosets H₁·x₀ with x₀ = F₁·σ·F₂⁻¹ and H₁ the common
symmetry group placed on body 1's feature (docs/algebra.md §3, §5.1; Liu & Popplestone
1990 eq. (1), Liu 1997 eq. (2)). The other relations (perpendicular, angle, point_on_plane,
point_on_line, distance) are not cosets; they, and all the others, have a residual vector for the
numeric residue solver (docs/algebra.md §2.5, numeric fallback). The coupled relations
(gear, rack, mirror) relate the motions of two bodies relative to a third (Corner et al.
1983 §III G; Liu 1997 Fig. 9): their residual takes the three world poses.

Residual scaling: every entry is a length in model units. Lengths enter as they are;
direction and angle entries (differences of unit vectors, cosines, sines) are multiplied
by the tolerance's arm ``tol.arm = tol.length / tol.angle`` (the model's bounding-box
diagonal when the angle tolerance follows the relative length, :mod:`assemblykit.tolerance`),
so an angular error θ weighs like the arc θ·arm, and one threshold ``tol.length`` holds
lengths to the length tolerance and angles to the angle tolerance.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from itertools import product
from types import MappingProxyType
from typing import Any, ClassVar, TypeVar

import numpy as np
from numpy.typing import NDArray

from assemblykit.algebra import Coset, EmptySet, Mismatch, MismatchKind, SymmetryGroup, se3
from assemblykit.errors import AssemblyKitError, FeatureError, SchemaError
from assemblykit.features.primitives import (
    Axis,
    Ball,
    Cone,
    Feature,
    Hole,
    Plane,
    Prism,
    Shaft,
    Socket,
    Thread,
    Torus,
    is_angle_text,
    parse_angle,
)
from assemblykit.tolerance import Tolerance, current

Matrix = NDArray[np.float64]
Residual = Callable[[Matrix], Matrix]
"""A residual of X = L_second⁻¹·L_first: zero iff the relation holds."""
CoupledResidual = Callable[[Sequence[Matrix]], Matrix]
"""A residual of the world poses ``(L_first, L_second, L_carrier)`` of a coupled relation."""
Equation = Callable[[Matrix, Matrix, Matrix, Matrix], Matrix]

AXIAL = frozenset({"shaft", "hole", "cone", "torus", "thread", "prism", "axis"})
"""Feature types carrying an axis line (frame +z along it)."""
POINTED = frozenset({"point", "ball", "socket", "cone", "torus", "frame"})
"""Feature types carrying a distinguished point (the frame origin: centre or apex)."""
DIRECTED = AXIAL | {"plane"}
"""Feature types carrying a direction (normal or axis, the frame +z)."""
LINED = AXIAL - POINTED
"""Feature types that are a line and nothing more (no distinguished point on it)."""


@dataclass(frozen=True)
class FeatureRef:
    """A reference ``body.feature`` to a feature of a body."""

    body: str
    feature: str

    @classmethod
    def parse(cls, text: str, where: str | None = None) -> FeatureRef:
        """Parse ``"body.feature"`` (split at the first dot)."""
        body, dot, feature = text.partition(".") if isinstance(text, str) else ("", "", "")
        if not (dot and body and feature):
            raise SchemaError(
                f"expected a feature reference 'body.feature', got {text!r}", where=where
            )
        return cls(body, feature)

    def __str__(self) -> str:
        return f"{self.body}.{self.feature}"


@dataclass(frozen=True)
class HeldPoint:
    """A point of one body held in an affine locus of the other: ``rows @ (y - origin) =
    0`` in the locus body's frame, ``rows`` orthonormal normals, one for a plane and two
    for a line (docs/algebra.md §3: the contact set of a point and a plane is
    Tr(plane)·S(point), not a coset). ``on_first`` says whether the point belongs to the
    first feature's body (the locus then belongs to the second's)."""

    on_first: bool
    point: Matrix
    origin: Matrix
    rows: Matrix


@dataclass(frozen=True)
class HeldLine:
    """A line of one body kept parallel to a plane of the other, at a signed distance
    along its normal (a cylinder on a plane, docs/algebra.md §3: a double coset of dimension
    3 + 2 − 1 = 4, not a coset). ``point`` and ``direction`` are in the line's body,
    ``origin`` (already offset by the distance) and ``normal`` in the plane's;
    ``on_first`` says whether the line belongs to the first feature's body."""

    on_first: bool
    point: Matrix
    direction: Matrix
    origin: Matrix
    normal: Matrix


def line_normals(direction: Matrix) -> Matrix:
    """Two orthonormal normals of a line of unit ``direction``."""
    basis = np.linalg.svd(direction.reshape(1, 3))[2]
    return basis[1:]


def _pairs(
    first: frozenset[str] | set[str], second: frozenset[str] | set[str]
) -> frozenset[tuple[str, str]]:
    return frozenset(product(first, second))


def _either(
    a: frozenset[str] | set[str], b: frozenset[str] | set[str]
) -> frozenset[tuple[str, str]]:
    return _pairs(a, b) | _pairs(b, a)


def _describe(feature: Feature) -> str:
    side = ""
    if isinstance(feature, Cone | Torus | Thread | Prism):
        side = "male " if feature.male else "female "
    return f"{side}{feature.type_name} '{feature.label}'"


class RelationType(ABC):
    """One relation kind ``[kind, first, second, {options}]`` (docs/tutorial.md §1).

    A subclass names the kind (``kind``), the (first, second) feature types it accepts,
    its option names (with the required ones), whether its set of X is a coset
    (``is_coset``, then :meth:`coset` gives it) and whether it couples motions through
    a third body (``coupled``, then :meth:`coupling` gives its residual). Every
    two-body kind has a :meth:`residual` and removes :meth:`dof_removed` dof; the higher
    pairs also give their :meth:`geometry` for the reduction's closed forms. The methods
    take features already checked by :meth:`check` and options validated by
    :meth:`values`.
    """

    kind: ClassVar[str]
    arity: ClassVar[int] = 2
    accepts: ClassVar[frozenset[tuple[str, str]]]
    options: ClassVar[frozenset[str]] = frozenset()
    required: ClassVar[frozenset[str]] = frozenset()
    is_coset: ClassVar[bool] = False
    coupled: ClassVar[bool] = False
    dof: ClassVar[int]
    """The dof removed from X (:meth:`dof_removed`, when it does not depend on the features)."""

    def accepts_pair(self, first: Feature, second: Feature) -> bool:
        """Whether the kind may relate these two features (by their types)."""
        return (first.type_name, second.type_name) in self.accepts

    def check(self, first: Feature, second: Feature, where: str | None = None) -> None:
        """:class:`FeatureError` naming ``where`` unless the kind may relate the features."""
        if not self.accepts_pair(first, second):
            raise FeatureError(
                f"{self.kind} cannot relate the {_describe(first)} and the {_describe(second)}",
                where=where,
            )

    def values(self, options: Mapping[str, Any], where: str | None = None) -> dict[str, float]:
        """Validated option values (``offset`` 0 unless given): unknown or missing names
        and non-numbers are schema errors; ``angle`` accepts ``"30 deg"``."""
        if unknown := sorted(map(str, set(options) - self.options)):
            allowed = ", ".join(sorted(self.options)) or "none"
            raise SchemaError(
                f"{self.kind} has no option {', '.join(unknown)} (allowed: {allowed})", where=where
            )
        if missing := sorted(self.required - set(options)):
            raise SchemaError(f"{self.kind} needs the option {', '.join(missing)}", where=where)
        values: dict[str, float] = {"offset": 0.0}
        for key, value in options.items():
            if key == "angle":
                values[key] = parse_angle(value, where)
            elif isinstance(value, str) and is_angle_text(value):
                raise SchemaError(
                    f"{self.kind} option {key} is a length in model units, not an angle: "
                    f"got {value!r}",
                    where=where,
                )
            elif (
                isinstance(value, bool)
                or not isinstance(value, int | float)
                or not math.isfinite(value)
            ):
                raise SchemaError(
                    f"{self.kind} option {key} must be a finite number, got {value!r}", where=where
                )
            else:
                values[key] = float(value)
        return values

    def coset(
        self, first: Feature, second: Feature, values: Mapping[str, float], tol: Tolerance
    ) -> Coset | EmptySet:
        """The set of X as a right coset H₁·x₀ in the second feature's body, or an
        inconsistency (coset kinds only)."""
        raise _not_a_coset(self.kind)

    @abstractmethod
    def residual(
        self, first: Feature, second: Feature, values: Mapping[str, float], tol: Tolerance
    ) -> Residual:
        """The residual r(X), zero iff X satisfies the relation; entries are lengths."""

    def dof_removed(self, first: Feature, second: Feature) -> int:
        """The generic number of dof the relation removes from X."""
        return self.dof

    def geometry(
        self, first: Feature, second: Feature, values: Mapping[str, float]
    ) -> HeldPoint | HeldLine | None:
        """The closed-form geometry of a higher pair, or None."""
        return None

    def coupling(
        self, first: Feature, second: Feature, values: Mapping[str, float], tol: Tolerance
    ) -> CoupledResidual:
        """The residual of a coupled relation over ``(L_first, L_second, L_carrier)``."""
        raise FeatureError(f"{self.kind} relates two bodies; it couples no motions")


_RELATIONS: dict[str, RelationType] = {}

RELATIONS: Mapping[str, RelationType] = MappingProxyType(_RELATIONS)
"""Every relation kind by name (DESIGN §5.1 and the extended vocabulary)."""

R = TypeVar("R", bound=type[RelationType])


def register_relation(cls: R) -> R:
    """Add the relation kind ``cls`` to :data:`RELATIONS` under ``cls.kind`` (usable as a
    class decorator); a name already taken is refused."""
    if cls.kind in _RELATIONS:
        raise AssemblyKitError(f"the relation {cls.kind!r} is already registered")
    _RELATIONS[cls.kind] = cls()
    return cls


def unregister_relation(kind: str) -> None:
    """Remove the relation kind ``kind`` from :data:`RELATIONS`."""
    del _RELATIONS[kind]


def relation_type(kind: str, where: str | None = None) -> RelationType:
    """The relation kind called ``kind``; :class:`SchemaError` naming ``where`` if none."""
    found = _RELATIONS.get(kind)
    if found is None:
        known = ", ".join(_RELATIONS)
        raise SchemaError(f"unknown relation {kind!r} (expected one of {known})", where=where)
    return found


def _not_a_coset(kind: str) -> FeatureError:
    return FeatureError(f"{kind} is not a coset relation; use its residual")


@dataclass(frozen=True)
class Relation:
    """A relation ``[kind, refs..., {options}]`` of a task; ``where`` locates it in its file."""

    kind: str
    refs: tuple[FeatureRef, ...]
    options: Mapping[str, Any] = field(default_factory=dict)
    where: str | None = None

    @classmethod
    def parse(cls, items: Any, where: str | None = None) -> Relation:
        """Parse the task-file list ``[kind, "b.f", "b.f", {options}]`` (DESIGN §5.1)."""
        if not isinstance(items, list | tuple) or not items or not isinstance(items[0], str):
            raise SchemaError(f"expected [kind, body.feature, ...], got {items!r}", where=where)
        kind, *rest = items
        options: Mapping[str, Any] = {}
        if rest and isinstance(rest[-1], Mapping):
            *rest, options = rest
        law = relation_type(kind, where)
        if len(rest) != law.arity:
            raise SchemaError(f"{kind} relates {law.arity} features, got {len(rest)}", where=where)
        values = law.values(options, where)
        refs = tuple(FeatureRef.parse(text, where) for text in rest)
        # the options given, as numbers (an angle written "30 deg" in radians)
        return cls(kind, refs, {key: values[key] for key in options}, where)

    @property
    def type(self) -> RelationType:
        """The relation kind (:data:`RELATIONS`)."""
        return relation_type(self.kind, self.where)

    @property
    def values(self) -> dict[str, float]:
        """The validated option values (:meth:`RelationType.values`)."""
        return self.type.values(self.options, self.where)


def check_relation(relation: Relation, first: Feature, second: Feature) -> None:
    """Check that ``relation`` may relate these features (types, sides, options).

    Raises :class:`FeatureError` (wrong feature types, e.g. ``against`` between a plane
    and a shaft) or :class:`SchemaError` (options), both naming ``relation.where``. A
    parameter mismatch (radii, lead, sides) is *not* an error: it makes the relation
    inconsistent, an answer given by :func:`relation_coset`."""
    if len(relation.refs) != 2:
        raise SchemaError(f"{relation.kind} relates 2 features", where=relation.where)
    relation.type.check(first, second, relation.where)
    relation.type.values(relation.options, relation.where)


def _checked(kind: str, first: Feature, second: Feature) -> RelationType:
    law = relation_type(kind)
    law.check(first, second)
    return law


def relation_coset(
    kind: str,
    first: Feature,
    second: Feature,
    options: Mapping[str, Any] | None = None,
    tol: Tolerance | None = None,
) -> Coset | EmptySet:
    """The set of X = L_second⁻¹·L_first allowed by ``[kind, first, second]`` as a right
    coset H₁·x₀ in the second feature's body (docs/algebra.md §3, §5.1), or an inconsistency
    (:meth:`RelationType.coset` of each kind).

    Raises :class:`FeatureError` for a kind that is not a coset or wrong feature types.
    """
    law = _checked(kind, first, second)
    if not law.is_coset:
        raise _not_a_coset(kind)
    return law.coset(first, second, law.values(options or {}), tol or current())


def relation_residual(
    kind: str,
    first: Feature,
    second: Feature,
    options: Mapping[str, Any] | None = None,
    tol: Tolerance | None = None,
) -> Residual:
    """The residual r(X) of ``[kind, first, second]``: zero iff X = L_second⁻¹·L_first
    satisfies the relation (the coset of :func:`relation_coset` for coset kinds;
    :meth:`RelationType.residual` of each kind). Entries are lengths; direction terms are
    scaled by ``tol.arm`` (module docstring). Coupled kinds (``gear``, ``rack``,
    ``mirror``) raise :class:`FeatureError`: they relate three bodies
    (:meth:`RelationType.coupling`)."""
    law = _checked(kind, first, second)
    return law.residual(first, second, law.values(options or {}), tol or current())


def relation_dof_removed(kind: str, first: Feature, second: Feature) -> int:
    """The generic number of dof ``[kind, first, second]`` removes from X: 6 minus the dof
    of its coset for coset kinds, and the number of independent scalar equations
    otherwise (:meth:`RelationType.dof_removed` of each kind)."""
    return _checked(kind, first, second).dof_removed(first, second)


# ------------------------------------------------------------------ shared pieces


def _is_directed(feature: Feature) -> bool:
    """Whether the feature's axis has an orientation: cones always, tori never (their
    surface has the flip, docs/algebra.md §4), the others as declared."""
    if isinstance(feature, Cone | Torus):
        return isinstance(feature, Cone)
    return bool(getattr(feature, "directed", True))


def _axis_of(feature: Feature) -> Axis:
    frame = feature.frame()
    return Axis(frame[:3, 3], frame[:3, 2], directed=_is_directed(feature))


def _aligned(first: Feature, second: Feature) -> Matrix:
    """F₁·F₂⁻¹ with F₁ = second.frame(), F₂ = first.frame()."""
    return second.frame() @ se3.inverse(first.frame())


def _equation(first: Feature, second: Feature, equation: Equation) -> Residual:
    """A residual from an equation on (d₁, o₁, d₂, o₂): the +z and origin of the second
    feature's frame F₁ and of the first feature's frame moved by X (X·F₂)."""
    f1, f2 = second.frame(), first.frame()
    d1, o1 = f1[:3, 2], f1[:3, 3]

    def residual(x: Matrix) -> Matrix:
        moved = np.asarray(x, dtype=np.float64) @ f2
        return equation(d1, o1, moved[:3, 2], moved[:3, 3])

    return residual


def _perpendicular_part(offset: Matrix, axis: Matrix) -> Matrix:
    return offset - (offset @ axis) * axis


def _canonical_axis_residual(g: Matrix, scale: float) -> Matrix:
    """Zero iff the canonical-frame motion g keeps the z-axis line with its direction."""
    return np.concatenate([(g[:3, 2] - (0.0, 0.0, 1.0)) * scale, g[:2, 3]])


def _discrete_residual(g: Matrix, feature: Feature) -> Matrix:
    """The helical (thread) or cyclic (prism) part, as a length: zero iff the rotation
    angle θ about z of g satisfies θ ≡ t_z/p (mod 2π) for a thread of pitch p, or
    θ ≡ 0 (mod 2π/n) for an n-sided prism (docs/algebra.md §2.3 membership, without a log)."""
    theta = math.atan2(g[1, 0], g[0, 0])
    if isinstance(feature, Thread):
        lag = g[2, 3] / feature.pitch
        return feature.radius * np.array(
            [math.cos(theta) - math.cos(lag), math.sin(theta) - math.sin(lag)]
        )
    if isinstance(feature, Prism):
        n = feature.sides
        return feature.size / n * np.array([math.cos(n * theta) - 1.0, math.sin(n * theta)])
    return np.zeros(0)


def _parameter_residual(first: Feature, second: Feature) -> Matrix:
    """Constant entries that are zero iff the ``fits`` parameters agree (lengths; the
    half-angle difference is taken as its chord on the unit circle times the radius 1)."""
    match first, second:
        case ((Shaft() | Hole() | Ball() | Socket()), (Shaft() | Hole() | Ball() | Socket())):
            return np.array([first.radius - second.radius])
        case Cone(), Cone():
            return np.array([math.sin(first.half_angle - second.half_angle)])
        case Torus(), Torus():
            return np.array(
                [first.major_radius - second.major_radius, first.minor_radius - second.minor_radius]
            )
        case Thread(), Thread():
            return np.array(
                [first.radius - second.radius, 2 * math.pi * (first.pitch - second.pitch)]
            )
        case Prism(), Prism():
            return np.array([float(first.sides - second.sides), first.size - second.size])
    return np.zeros(0)


def _fits_residual(first: Feature, second: Feature, scale: float) -> Residual:
    """Residual of ``fits`` (and ``coaxial``) on the pair of frames (G₂ = X·F₂, F₁); the
    flip is allowed unless both features are directed."""
    f1 = second.frame()
    inv_f1 = se3.inverse(f1)
    flip = se3.rot_x(math.pi)
    constant = _parameter_residual(first, second)
    spherical = isinstance(second, Ball | Socket)
    directed = _is_directed(first) and _is_directed(second)

    def canonical(g: Matrix) -> Matrix:
        if spherical:
            return g[:3, 3]
        parts = [_canonical_axis_residual(g, scale), _discrete_residual(g, second)]
        if isinstance(second, Cone | Torus):
            parts.append(g[2:3, 3])
        return np.concatenate(parts)

    def residual(moved: Matrix) -> Matrix:
        g = inv_f1 @ moved
        best = canonical(g)
        if not directed:
            other = canonical(g @ flip)
            best = other if float(other @ other) < float(best @ best) else best
        return np.concatenate([best, constant])

    return residual


def _moving(first: Feature, on_frames: Residual) -> Residual:
    """A residual of X from one of the first feature's frame moved by X (X·F₂)."""
    f2 = first.frame()
    return lambda x: on_frames(np.asarray(x, dtype=np.float64) @ f2)


def _fits_group(first: Feature, second: Feature) -> SymmetryGroup:
    """The common symmetry group on body 1's feature; the pair is directed only when both
    features are (an undirected hole takes a directed shaft either way round)."""
    if hasattr(second, "directed"):
        directed = second.directed and first.directed  # type: ignore[attr-defined]
        return replace(second, directed=directed).group()  # type: ignore[type-var]
    return second.group()


def _mismatch(kind: MismatchKind, first: float, second: float, what: str) -> EmptySet:
    return EmptySet(
        Mismatch(kind, abs(first - second), f"{what} {first:g} vs {second:g}"), proven=True
    )


def _fits_mismatch(first: Feature, second: Feature, tol: Tolerance) -> EmptySet | None:
    """The precondition of ``fits`` (docs/algebra.md §4 table): equal radii, half-angle, lead,
    hand, sides and size; the first failing one as an inconsistency."""
    checks: list[tuple[MismatchKind, float, float, str, float]] = []
    match first, second:
        case ((Shaft() | Hole() | Ball() | Socket()), (Shaft() | Hole() | Ball() | Socket())):
            checks.append((MismatchKind.RADIUS, first.radius, second.radius, "radius", tol.length))
        case Cone(), Cone():
            checks.append(
                (MismatchKind.ANGLE, first.half_angle, second.half_angle, "half-angle", tol.angle)
            )
        case Torus(), Torus():
            checks.append(
                (
                    MismatchKind.RADIUS,
                    first.major_radius,
                    second.major_radius,
                    "major radius",
                    tol.length,
                )
            )
            checks.append(
                (
                    MismatchKind.RADIUS,
                    first.minor_radius,
                    second.minor_radius,
                    "minor radius",
                    tol.length,
                )
            )
        case Thread(), Thread():
            checks.append((MismatchKind.RADIUS, first.radius, second.radius, "radius", tol.length))
            checks.append((MismatchKind.PITCH, first.lead, second.lead, "lead", tol.length))
            if first.hand != second.hand:
                return EmptySet(
                    Mismatch(
                        MismatchKind.HANDEDNESS,
                        2 * first.lead,
                        f"hand {first.hand} vs {second.hand}",
                    ),
                    proven=True,
                )
        case Prism(), Prism():
            checks.append((MismatchKind.SIDES, first.sides, second.sides, "sides", 0.5))
            checks.append((MismatchKind.SIZE, first.size, second.size, "size", tol.length))
    for kind, a, b, what, limit in checks:
        if abs(a - b) > limit:
            return _mismatch(kind, a, b, what)
    return None


def _held_point(
    first: Feature, second: Feature, on_first: bool, offset: float, line: bool
) -> HeldPoint:
    """A point of one feature held in the plane (offset along its normal) or on the line
    of the other (``on_first``: the point is the first feature's)."""
    feature, locus = (first, second) if on_first else (second, first)
    frame = locus.frame()
    axis = frame[:3, 2]
    point = feature.frame()[:3, 3]
    if line:
        return HeldPoint(on_first, point, frame[:3, 3], line_normals(axis))
    return HeldPoint(on_first, point, frame[:3, 3] + offset * axis, axis.reshape(1, 3))


# ------------------------------------------------------------------ the kinds


@register_relation
class Against(RelationType):
    """Planes touching with opposed normals, a gap ``offset`` along n₁:
    G(n₁)·F₁·Tr(0,0,offset)·Rx(π)·F₂⁻¹ (with F₁ = second.frame(), F₂ = first.frame());
    3 dof removed."""

    kind = "against"
    accepts = _pairs({"plane"}, {"plane"})
    options = frozenset({"offset"})
    is_coset = True
    dof = 3

    def coset(
        self, first: Feature, second: Feature, values: Mapping[str, float], tol: Tolerance
    ) -> Coset | EmptySet:
        f1 = second.frame()
        rep = f1 @ se3.translation((0.0, 0.0, values["offset"])) @ se3.rot_x(math.pi)
        return Coset(second.group(), rep @ se3.inverse(first.frame()))

    def residual(
        self, first: Feature, second: Feature, values: Mapping[str, float], tol: Tolerance
    ) -> Residual:
        arm, offset = tol.arm, values["offset"]
        return _equation(
            first,
            second,
            lambda d1, o1, d2, o2: np.append((d2 + d1) * arm, d1 @ (o2 - o1) - offset),
        )


@register_relation
class Coplanar(RelationType):
    """Planes coinciding with equal normals: G(n₁)·F₁F₂⁻¹; 3 dof removed."""

    kind = "coplanar"
    accepts = _pairs({"plane"}, {"plane"})
    is_coset = True
    dof = 3

    def coset(
        self, first: Feature, second: Feature, values: Mapping[str, float], tol: Tolerance
    ) -> Coset | EmptySet:
        return Coset(second.group(), _aligned(first, second))

    def residual(
        self, first: Feature, second: Feature, values: Mapping[str, float], tol: Tolerance
    ) -> Residual:
        arm = tol.arm
        return _equation(
            first, second, lambda d1, o1, d2, o2: np.append((d2 - d1) * arm, d1 @ (o2 - o1))
        )


_FITS_DOF = {
    "shaft": 4,
    "hole": 4,
    "ball": 3,
    "socket": 3,
    "cone": 5,
    "torus": 5,
    "thread": 5,
    "prism": 5,
}


@register_relation
class Fits(RelationType):
    """A lower pair of equal features (shaft in hole, ball in socket, cone, torus,
    thread, prism, male in female): their common group (C, S, R, H, T⋊Cₙ; with the flip
    unless both features are directed) times F₁F₂⁻¹. Unequal parameters give an
    :class:`EmptySet` whose :class:`Mismatch` kind is ``radius``, ``angle``, ``pitch``,
    ``handedness``, ``sides`` or ``size``. Removes 6 minus the group's dof (C 4, S 3,
    R 5, H 5, T⋊Cₙ 5)."""

    kind = "fits"
    accepts = (
        _either({"shaft"}, {"hole"})
        | _either({"ball"}, {"socket"})
        | frozenset((kind, kind) for kind in ("cone", "torus", "thread", "prism"))
    )
    is_coset = True

    def accepts_pair(self, first: Feature, second: Feature) -> bool:
        """The types fit and, for sided features, one is male and the other female."""
        sided = Cone | Torus | Thread | Prism
        if isinstance(first, sided) and isinstance(second, sided):
            return super().accepts_pair(first, second) and first.male != second.male
        return super().accepts_pair(first, second)

    def coset(
        self, first: Feature, second: Feature, values: Mapping[str, float], tol: Tolerance
    ) -> Coset | EmptySet:
        return _fits_mismatch(first, second, tol) or Coset(
            _fits_group(first, second), _aligned(first, second)
        )

    def residual(
        self, first: Feature, second: Feature, values: Mapping[str, float], tol: Tolerance
    ) -> Residual:
        return _moving(first, _fits_residual(first, second, tol.arm))

    def dof_removed(self, first: Feature, second: Feature) -> int:
        return _FITS_DOF[second.type_name]


@register_relation
class Coaxial(RelationType):
    """Axis lines coinciding: C(axis₁) (⋊ flip unless both directed) times F₁F₂⁻¹;
    4 dof removed."""

    kind = "coaxial"
    accepts = _pairs(AXIAL, AXIAL)
    is_coset = True
    dof = 4

    def coset(
        self, first: Feature, second: Feature, values: Mapping[str, float], tol: Tolerance
    ) -> Coset | EmptySet:
        return Coset(_fits_group(_axis_of(first), _axis_of(second)), _aligned(first, second))

    def residual(
        self, first: Feature, second: Feature, values: Mapping[str, float], tol: Tolerance
    ) -> Residual:
        return _moving(first, _fits_residual(_axis_of(first), _axis_of(second), tol.arm))


@register_relation
class Fixed(RelationType):
    """Datum frames coinciding: {F₁F₂⁻¹}; 6 dof removed. Only datum frames fix every
    axis; other features' x axes are arbitrary."""

    kind = "fixed"
    accepts = _pairs({"frame"}, {"frame"})
    is_coset = True
    dof = 6

    def coset(
        self, first: Feature, second: Feature, values: Mapping[str, float], tol: Tolerance
    ) -> Coset | EmptySet:
        return Coset(SymmetryGroup.identity(), _aligned(first, second))

    def residual(
        self, first: Feature, second: Feature, values: Mapping[str, float], tol: Tolerance
    ) -> Residual:
        arm = tol.arm
        f1, f2 = second.frame(), first.frame()

        def residual(x: Matrix) -> Matrix:
            moved = np.asarray(x, dtype=np.float64) @ f2
            return np.concatenate(
                [(moved[:3, :3] - f1[:3, :3]).ravel() * arm, moved[:3, 3] - f1[:3, 3]]
            )

        return residual


@register_relation
class Parallel(RelationType):
    """Directions parallel, either way round: X(d₁)⋊⟨flip⟩ times F₁F₂⁻¹ (unoriented
    directions, 2 components); 2 dof removed."""

    kind = "parallel"
    accepts = _pairs(DIRECTED, DIRECTED)
    is_coset = True
    dof = 2

    def coset(
        self, first: Feature, second: Feature, values: Mapping[str, float], tol: Tolerance
    ) -> Coset | EmptySet:
        f1 = second.frame()
        flip = f1 @ se3.rot_x(math.pi) @ se3.inverse(f1)
        group = SymmetryGroup.schoenflies(f1[:3, 2]).with_discrete(reps=(flip,))
        return Coset(group, _aligned(first, second))

    def residual(
        self, first: Feature, second: Feature, values: Mapping[str, float], tol: Tolerance
    ) -> Residual:
        arm = tol.arm
        return _equation(first, second, lambda d1, o1, d2, o2: np.cross(d2, d1) * arm)


@register_relation
class Perpendicular(RelationType):
    """Directions perpendicular: d₂·d₁ = 0; 1 dof removed."""

    kind = "perpendicular"
    accepts = _pairs(DIRECTED, DIRECTED)
    dof = 1

    def residual(
        self, first: Feature, second: Feature, values: Mapping[str, float], tol: Tolerance
    ) -> Residual:
        arm = tol.arm
        return _equation(first, second, lambda d1, o1, d2, o2: np.array([d2 @ d1 * arm]))


@register_relation
class Angle(RelationType):
    """Directions at an ``angle``: d₂·d₁ = cos(angle); 1 dof removed."""

    kind = "angle"
    accepts = _pairs(DIRECTED, DIRECTED)
    options = frozenset({"angle"})
    required = frozenset({"angle"})
    dof = 1

    def residual(
        self, first: Feature, second: Feature, values: Mapping[str, float], tol: Tolerance
    ) -> Residual:
        arm, cosine = tol.arm, math.cos(values["angle"])
        return _equation(first, second, lambda d1, o1, d2, o2: np.array([(d2 @ d1 - cosine) * arm]))


@register_relation
class Coincident(RelationType):
    """Points (centres, apexes) coinciding: S(c₁)·Tr(c₁ − c₂); 3 dof removed."""

    kind = "coincident"
    accepts = _pairs(POINTED, POINTED)
    is_coset = True
    dof = 3

    def coset(
        self, first: Feature, second: Feature, values: Mapping[str, float], tol: Tolerance
    ) -> Coset | EmptySet:
        centre1, centre2 = second.frame()[:3, 3], first.frame()[:3, 3]
        return Coset(SymmetryGroup.spherical(centre1), se3.translation(centre1 - centre2))

    def residual(
        self, first: Feature, second: Feature, values: Mapping[str, float], tol: Tolerance
    ) -> Residual:
        return _equation(first, second, lambda d1, o1, d2, o2: o2 - o1)


@register_relation
class PointOnPlane(RelationType):
    """A point (centre, apex) in a plane, either order: n·(c − p) = 0; 1 dof removed."""

    kind = "point_on_plane"
    accepts = _either(POINTED, {"plane"})
    dof = 1

    def residual(
        self, first: Feature, second: Feature, values: Mapping[str, float], tol: Tolerance
    ) -> Residual:
        if isinstance(second, Plane):
            return _equation(first, second, lambda d1, o1, d2, o2: np.array([d1 @ (o2 - o1)]))
        return _equation(first, second, lambda d1, o1, d2, o2: np.array([d2 @ (o1 - o2)]))

    def geometry(
        self, first: Feature, second: Feature, values: Mapping[str, float]
    ) -> HeldPoint | HeldLine | None:
        return _held_point(first, second, second.type_name == "plane", 0.0, line=False)


@register_relation
class PointOnLine(RelationType):
    """A point on an axis line, either order: the offset of c from the line is 0;
    2 dof removed."""

    kind = "point_on_line"
    accepts = _either(POINTED, AXIAL)
    dof = 2

    def residual(
        self, first: Feature, second: Feature, values: Mapping[str, float], tol: Tolerance
    ) -> Residual:
        if second.type_name in AXIAL:
            return _equation(first, second, lambda d1, o1, d2, o2: _perpendicular_part(o2 - o1, d1))
        return _equation(first, second, lambda d1, o1, d2, o2: _perpendicular_part(o1 - o2, d2))

    def geometry(
        self, first: Feature, second: Feature, values: Mapping[str, float]
    ) -> HeldPoint | HeldLine | None:
        return _held_point(first, second, second.type_name in AXIAL, 0.0, line=True)


@register_relation
class Distance(RelationType):
    """A ``distance`` d: ‖c₂ − c₁‖ = d (points), n·(c − p) = d (a point and a plane,
    signed along the normal), the line parallel to the plane with n·(o − p) = d (a line
    and a plane: a cylinder of radius d lying on the plane, docs/algebra.md §3), planes
    parallel with n₁·(p₂ − p₁) = d (two planes). Removes 1 dof, 2 between a line and a
    plane, 3 between two planes."""

    kind = "distance"
    accepts = (
        _pairs(POINTED, POINTED)
        | _either(POINTED, {"plane"})
        | _either(LINED, {"plane"})
        | _pairs({"plane"}, {"plane"})
    )
    options = frozenset({"distance"})
    required = frozenset({"distance"})

    def residual(
        self, first: Feature, second: Feature, values: Mapping[str, float], tol: Tolerance
    ) -> Residual:
        arm, distance = tol.arm, values["distance"]
        equation: Equation
        if isinstance(first, Plane) and isinstance(second, Plane):

            def equation(d1: Matrix, o1: Matrix, d2: Matrix, o2: Matrix) -> Matrix:
                return np.append(np.cross(d2, d1) * arm, d1 @ (o2 - o1) - distance)

        elif isinstance(second, Plane) and first.type_name in LINED:

            def equation(d1: Matrix, o1: Matrix, d2: Matrix, o2: Matrix) -> Matrix:
                return np.array([d2 @ d1 * arm, d1 @ (o2 - o1) - distance])

        elif isinstance(first, Plane) and second.type_name in LINED:

            def equation(d1: Matrix, o1: Matrix, d2: Matrix, o2: Matrix) -> Matrix:
                return np.array([d1 @ d2 * arm, d2 @ (o1 - o2) - distance])

        elif isinstance(second, Plane):

            def equation(d1: Matrix, o1: Matrix, d2: Matrix, o2: Matrix) -> Matrix:
                return np.array([d1 @ (o2 - o1) - distance])

        elif isinstance(first, Plane):

            def equation(d1: Matrix, o1: Matrix, d2: Matrix, o2: Matrix) -> Matrix:
                return np.array([d2 @ (o1 - o2) - distance])

        else:

            def equation(d1: Matrix, o1: Matrix, d2: Matrix, o2: Matrix) -> Matrix:
                return np.array([np.linalg.norm(o2 - o1) - distance])

        return _equation(first, second, equation)

    def dof_removed(self, first: Feature, second: Feature) -> int:
        if isinstance(first, Plane) and isinstance(second, Plane):
            return 3
        return 2 if LINED & {first.type_name, second.type_name} else 1

    def geometry(
        self, first: Feature, second: Feature, values: Mapping[str, float]
    ) -> HeldPoint | HeldLine | None:
        """A point or a line and a plane, the plane offset along its normal by the
        distance (either order); None between two points or two planes."""
        types = (first.type_name, second.type_name)
        if "plane" not in types or types[0] == types[1]:
            return None
        on_first = types[1] == "plane"
        feature, plane = (first, second) if on_first else (second, first)
        frame = plane.frame()
        normal = frame[:3, 2]
        if feature.type_name in LINED:
            own = feature.frame()
            origin = frame[:3, 3] + values["distance"] * normal
            return HeldLine(on_first, own[:3, 3], own[:3, 2], origin, normal)
        return _held_point(first, second, on_first, values["distance"], line=False)


# ------------------------------------------------------------------ coupled kinds


def wrap_angle(angle: float) -> float:
    """The angle in (-π, π]."""
    return float(np.pi - np.mod(np.pi - angle, 2 * np.pi))


def _cross(a: Matrix, b: Matrix) -> Matrix:
    """Cross product of two 3-vectors (np.cross is slow on single small vectors)."""
    return np.array(
        [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
    )


def signed_angle(a: Matrix, b: Matrix, axis: Matrix) -> float:
    """The angle from ``a`` to ``b`` measured counter-clockwise about the unit ``axis``."""
    return float(np.arctan2(np.dot(_cross(a, b), axis), np.dot(a, b)))


def _rotation_angle(rotation: Matrix, axis: Matrix) -> float:
    """The angle θ of a rotation matrix about the unit ``axis`` (exact when the rotation is
    about that axis): the signed angle from a vector perpendicular to the axis to its image."""
    ortho = se3.axis_basis(axis)[0]
    return signed_angle(ortho, rotation @ ortho, axis)


class CoupledRelation(RelationType):
    """A relation that couples the motions of two bodies relative to a carrier, the
    body both are related to (Corner et al. 1983 §III G; Liu 1997 Fig. 9). In the
    reference pose every body frame coincides with the carrier's frame, so the features
    in body coordinates are the features in the carrier. It has no pair residual and no
    pair dof: its semantics belong to the network (:meth:`coupling`)."""

    coupled = True

    def residual(
        self, first: Feature, second: Feature, values: Mapping[str, float], tol: Tolerance
    ) -> Residual:
        raise FeatureError(
            f"{self.kind} couples motions through the network; it has no pair residual"
        )

    def dof_removed(self, first: Feature, second: Feature) -> int:
        raise FeatureError(f"{self.kind} couples motions through the network; it has no pair dof")

    @abstractmethod
    def coupling(
        self, first: Feature, second: Feature, values: Mapping[str, float], tol: Tolerance
    ) -> CoupledResidual:
        """The residual over the world poses ``(L_first, L_second, L_carrier)``."""


def gear_residual(
    first_frame: Matrix, second_frame: Matrix, ratio: float, scale: float = 1.0
) -> CoupledResidual:
    """The coupled relation ``gear``: two bodies turning about their axes in a fixed ratio.

    Semantics (Liu 1997 Fig. 9: gears on a common carrier): each body turns about its
    feature's axis (+z of ``first_frame`` / ``second_frame``) relative to the carrier (the
    body both gears are related to; their revolute joints are separate relations). In the
    reference pose every body frame coincides with the carrier's frame, so the axes in
    body coordinates are the axes in the carrier. With ``X1``, ``X2`` the gears' poses in
    the carrier and θi the rotation angle of ``Xi`` about axis i (0 in the reference
    pose), the relation holds when ``θ2 = ratio·θ1`` (angles in (-π, π]; an external spur
    pair with n1 and n2 teeth has ``ratio = -n1/n2``). The residual is that angle
    difference times ``scale`` (a length, like every residual). It takes the world poses
    ``(L1, L2, L_carrier)``.
    """
    axis1, axis2 = first_frame[:3, 2], second_frame[:3, 2]

    def residual(poses: Sequence[Matrix]) -> Matrix:
        to_carrier = np.linalg.inv(poses[2])[:3, :3]
        theta1 = _rotation_angle(to_carrier @ poses[0][:3, :3], axis1)
        theta2 = _rotation_angle(to_carrier @ poses[1][:3, :3], axis2)
        return np.array([wrap_angle(theta2 - ratio * theta1) * scale])

    return residual


def rack_residual(pinion_frame: Matrix, rack_frame: Matrix, radius: float) -> CoupledResidual:
    """The coupled relation ``rack``: a pinion turning about its axis drives a rack along
    its line (Liu 1997 Fig. 9, a gear pair whose second gear has an infinite radius).

    Semantics as :func:`gear_residual`: both bodies move relative to the carrier (the
    body both are related to; the pinion's revolute and the rack's slide are separate
    relations), and in the reference pose every body frame coincides with the
    carrier's. With θ the pinion's turn about its axis (+z of ``pinion_frame``, the
    principal angle in (-π, π] as for ``gear``) and ``s`` the rack's displacement along
    its line (+z of ``rack_frame``), the relation holds when ``s = radius·θ``: the pitch
    circle rolls on the rack's pitch line without slipping. The residual is that length
    difference. It takes the world poses ``(L_pinion, L_rack, L_carrier)``.
    """
    axis, direction = pinion_frame[:3, 2], rack_frame[:3, 2]
    origin = np.append(rack_frame[:3, 3], 1.0)

    def residual(poses: Sequence[Matrix]) -> Matrix:
        to_carrier = np.linalg.inv(poses[2])
        theta = _rotation_angle(to_carrier[:3, :3] @ poses[0][:3, :3], axis)
        shift = float(direction @ ((to_carrier @ poses[1] @ origin)[:3] - origin[:3]))
        return np.array([shift - radius * theta])

    return residual


def mirror_residual(
    first_frame: Matrix, second_frame: Matrix, direction: Matrix
) -> CoupledResidual:
    """The coupled relation ``mirror``: two bodies moving equal and opposite along a direction.

    Semantics (Corner et al. 1983 §III G: gripper jaws "constrained to move in equal and opposite
    directions by the same amount"): the jaws move relative to a carrier (the palm, the
    body both jaws are related to). In the reference pose every body frame coincides with
    the carrier's frame, so the features' origins ``o1``, ``o2`` (in their bodies) are
    their reference positions in the carrier. With ``X1``, ``X2`` the jaws' poses in the
    carrier and ``n`` the unit ``direction`` (in the carrier), the displacements along
    ``n`` are opposite: ``n·(X1 o1 - o1) + n·(X2 o2 - o2) = 0``, i.e. the midpoint of the
    two features keeps its reference position along ``n``. Other freedoms of the jaws are
    left to their own relations (usually a prismatic joint each to the palm). The
    residual takes the world poses ``(L1, L2, L_carrier)``.
    """
    o1, o2 = first_frame[:3, 3], second_frame[:3, 3]

    def residual(poses: Sequence[Matrix]) -> Matrix:
        to_carrier = np.linalg.inv(poses[2])
        moved1 = (to_carrier @ poses[0])[:3] @ np.append(o1, 1.0)
        moved2 = (to_carrier @ poses[1])[:3] @ np.append(o2, 1.0)
        return np.array([np.dot(direction, moved1 - o1 + moved2 - o2)])

    return residual


@register_relation
class Gear(CoupledRelation):
    """Two axes turning in the fixed ``ratio`` θ₂ = ratio·θ₁ (:func:`gear_residual`)."""

    kind = "gear"
    accepts = _pairs(AXIAL, AXIAL)
    options = frozenset({"ratio"})
    required = frozenset({"ratio"})

    def coupling(
        self, first: Feature, second: Feature, values: Mapping[str, float], tol: Tolerance
    ) -> CoupledResidual:
        return gear_residual(first.frame(), second.frame(), values["ratio"], tol.arm)


@register_relation
class Rack(CoupledRelation):
    """A pinion's turn θ driving a rack along its line by ``radius``·θ
    (:func:`rack_residual`)."""

    kind = "rack"
    accepts = _pairs(AXIAL, AXIAL)
    options = frozenset({"radius"})
    required = frozenset({"radius"})

    def coupling(
        self, first: Feature, second: Feature, values: Mapping[str, float], tol: Tolerance
    ) -> CoupledResidual:
        return rack_residual(first.frame(), second.frame(), values["radius"])


@register_relation
class Mirror(CoupledRelation):
    """Two planes or points moving equal and opposite, along the first plane's normal or
    the line through the two points (:func:`mirror_residual`). Two coincident points
    give no direction: a :class:`SchemaError`."""

    kind = "mirror"
    accepts = _pairs({"plane", "point"}, {"plane", "point"})

    def coupling(
        self, first: Feature, second: Feature, values: Mapping[str, float], tol: Tolerance
    ) -> CoupledResidual:
        frames = first.frame(), second.frame()
        direction = frames[0][:3, 2]
        if first.type_name != "plane":
            offset = frames[1][:3, 3] - frames[0][:3, 3]
            if not np.linalg.norm(offset) > 0:
                raise SchemaError("mirror: the two points coincide, so they give no direction")
            direction = offset / np.linalg.norm(offset)
        return mirror_residual(*frames, direction)
