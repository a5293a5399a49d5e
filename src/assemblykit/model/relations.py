"""The relation vocabulary: what each relation accepts, its coset and its residual.

A relation ``[kind, first, second, {options}]`` between features of two bodies constrains
X = L₂⁻¹·L₁, the pose of the *first* feature's body in the frame of the *second*
feature's body (ALGEBRA.md §5.1: the second feature's body is body 1, the "from" side).
So ``[against, block.bottom, table.top]`` is the set of block poses in the table frame.

Lower-pair relations are right cosets H₁·x₀ with x₀ = F₁·σ·F₂⁻¹ and H₁ the common
symmetry group placed on body 1's feature (ALGEBRA.md §3, §5.1; Liu & Popplestone 1990 eq. (1), seed
003 eq. (2)). The other relations (perpendicular, angle, point_on_plane, point_on_line,
distance) are not cosets; they, and all the others, have a residual vector for the
numeric residue solver (ALGEBRA.md §2.5, numeric fallback).

Residual scaling: every entry is a length in model units. Lengths enter as they are;
direction and angle entries (differences of unit vectors, cosines, sines) are multiplied
by the tolerance's arm ``tol.arm = tol.length / tol.angle`` (the model's bounding-box
diagonal when the angle tolerance follows the relative length, :mod:`assemblykit.tolerance`),
so an angular error θ weighs like the arc θ·arm, and one threshold ``tol.length`` holds
lengths to the length tolerance and angles to the angle tolerance.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from itertools import product
from types import MappingProxyType
from typing import Any

import numpy as np
from numpy.typing import NDArray

from assemblykit.algebra import Coset, EmptySet, Mismatch, SymmetryGroup, se3
from assemblykit.errors import FeatureError, SchemaError
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
    parse_angle,
)
from assemblykit.tolerance import Tolerance, current

Residual = Callable[[NDArray[np.float64]], NDArray[np.float64]]

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
class RelationSpec:
    """One relation kind: its arity, accepted (first, second) feature types, option names
    (with the required ones), and whether its set is a coset."""

    kind: str
    arity: int
    accepts: frozenset[tuple[str, str]]
    options: frozenset[str] = frozenset()
    required: frozenset[str] = frozenset()
    coset: bool = False


def _pairs(first: frozenset[str] | set[str], second: frozenset[str] | set[str]) -> frozenset:
    return frozenset(product(first, second))


def _either(a: frozenset[str] | set[str], b: frozenset[str] | set[str]) -> frozenset:
    return _pairs(a, b) | _pairs(b, a)


_FITS = (
    _either({"shaft"}, {"hole"})
    | _either({"ball"}, {"socket"})
    | frozenset((kind, kind) for kind in ("cone", "torus", "thread", "prism"))
)

RELATIONS: Mapping[str, RelationSpec] = MappingProxyType(
    {
        spec.kind: spec
        for spec in (
            RelationSpec(
                "against", 2, _pairs({"plane"}, {"plane"}), frozenset({"offset"}), coset=True
            ),
            RelationSpec("coplanar", 2, _pairs({"plane"}, {"plane"}), coset=True),
            RelationSpec("fits", 2, _FITS, coset=True),
            RelationSpec("coaxial", 2, _pairs(AXIAL, AXIAL), coset=True),
            # Only datum frames fix every axis; other features' x axes are arbitrary.
            RelationSpec("fixed", 2, _pairs({"frame"}, {"frame"}), coset=True),
            RelationSpec("parallel", 2, _pairs(DIRECTED, DIRECTED), coset=True),
            RelationSpec("perpendicular", 2, _pairs(DIRECTED, DIRECTED)),
            RelationSpec(
                "angle", 2, _pairs(DIRECTED, DIRECTED), frozenset({"angle"}), frozenset({"angle"})
            ),
            RelationSpec("coincident", 2, _pairs(POINTED, POINTED), coset=True),
            RelationSpec("point_on_plane", 2, _either(POINTED, {"plane"})),
            RelationSpec("point_on_line", 2, _either(POINTED, AXIAL)),
            RelationSpec(
                "distance",
                2,
                _pairs(POINTED, POINTED)
                | _either(POINTED, {"plane"})
                | _either(LINED, {"plane"})
                | _pairs({"plane"}, {"plane"}),
                frozenset({"distance"}),
                frozenset({"distance"}),
            ),
            RelationSpec(
                "gear", 2, _pairs(AXIAL, AXIAL), frozenset({"ratio"}), frozenset({"ratio"})
            ),
            RelationSpec(
                "rack", 2, _pairs(AXIAL, AXIAL), frozenset({"radius"}), frozenset({"radius"})
            ),
            RelationSpec("mirror", 2, _pairs({"plane", "point"}, {"plane", "point"})),
        )
    }
)
"""Every relation kind (DESIGN §5.1 and the extended vocabulary)."""

COUPLED = frozenset({"gear", "rack", "mirror"})
"""Relations that couple motions through a third body; their semantics belong to the
network (``assemblykit.inference``), not to a pair of features."""


def _spec(kind: str, where: str | None) -> RelationSpec:
    if kind not in RELATIONS:
        known = ", ".join(RELATIONS)
        raise SchemaError(f"unknown relation {kind!r} (expected one of {known})", where=where)
    return RELATIONS[kind]


def _option_values(kind: str, options: Mapping[str, Any], where: str | None) -> dict[str, float]:
    """Validated option values: unknown or missing names and non-numbers are schema errors;
    ``angle`` accepts ``"30 deg"``."""
    spec = _spec(kind, where)
    if unknown := sorted(set(options) - spec.options):
        allowed = ", ".join(sorted(spec.options)) or "none"
        raise SchemaError(
            f"{kind} has no option {', '.join(unknown)} (allowed: {allowed})", where=where
        )
    if missing := sorted(spec.required - set(options)):
        raise SchemaError(f"{kind} needs the option {', '.join(missing)}", where=where)
    values: dict[str, float] = {"offset": 0.0}
    for key, value in options.items():
        if key == "angle":
            values[key] = parse_angle(value, where)
        elif (
            isinstance(value, bool)
            or not isinstance(value, int | float)
            or not math.isfinite(value)
        ):
            raise SchemaError(
                f"{kind} option {key} must be a finite number, got {value!r}", where=where
            )
        else:
            values[key] = float(value)
    return values


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
        spec = _spec(kind, where)
        if len(rest) != spec.arity:
            raise SchemaError(f"{kind} relates {spec.arity} features, got {len(rest)}", where=where)
        _option_values(kind, options, where)
        refs = tuple(FeatureRef.parse(text, where) for text in rest)
        return cls(kind, refs, dict(options), where)


def _describe(feature: Feature) -> str:
    side = ""
    if isinstance(feature, Cone | Torus | Thread | Prism):
        side = "male " if feature.male else "female "
    return f"{side}{feature.type_name} '{feature.label}'"


def _check(kind: str, first: Feature, second: Feature, where: str | None) -> RelationSpec:
    spec = _spec(kind, where)
    accepted = (first.type_name, second.type_name) in spec.accepts
    sided = Cone | Torus | Thread | Prism
    if accepted and kind == "fits" and isinstance(first, sided) and isinstance(second, sided):
        accepted = first.male != second.male
    if not accepted:
        raise FeatureError(
            f"{kind} cannot relate the {_describe(first)} and the {_describe(second)}", where=where
        )
    return spec


def check_relation(relation: Relation, first: Feature, second: Feature) -> None:
    """Check that ``relation`` may relate these features (types, sides, options).

    Raises :class:`FeatureError` (wrong feature types, e.g. ``against`` between a plane
    and a shaft) or :class:`SchemaError` (options), both naming ``relation.where``. A
    parameter mismatch (radii, lead, sides) is *not* an error: it makes the relation
    inconsistent, an answer given by :func:`relation_coset`."""
    if len(relation.refs) != 2:
        raise SchemaError(f"{relation.kind} relates 2 features", where=relation.where)
    _check(relation.kind, first, second, relation.where)
    _option_values(relation.kind, relation.options, relation.where)


def _is_directed(feature: Feature) -> bool:
    """Whether the feature's axis has an orientation: cones always, tori never (their
    surface has the flip, ALGEBRA.md §4), the others as declared."""
    if isinstance(feature, Cone | Torus):
        return isinstance(feature, Cone)
    return bool(getattr(feature, "directed", True))


def _axis_of(feature: Feature) -> Axis:
    frame = feature.frame()
    return Axis(frame[:3, 3], frame[:3, 2], directed=_is_directed(feature))


def _mismatch(kind: str, first: float, second: float, what: str) -> EmptySet:
    return EmptySet(
        Mismatch(kind, abs(first - second), f"{what} {first:g} vs {second:g}"), proven=True
    )


def _fits_mismatch(first: Feature, second: Feature, tol: Tolerance) -> EmptySet | None:
    """The precondition of ``fits`` (ALGEBRA.md §4 table): equal radii, half-angle, lead,
    hand, sides and size; the first failing one as an inconsistency."""
    checks: list[tuple[str, float, float, str, float]] = []
    match first, second:
        case ((Shaft() | Hole() | Ball() | Socket()), (Shaft() | Hole() | Ball() | Socket())):
            checks.append(("radius", first.radius, second.radius, "radius", tol.length))
        case Cone(), Cone():
            checks.append(("angle", first.half_angle, second.half_angle, "half-angle", tol.angle))
        case Torus(), Torus():
            checks.append(
                ("radius", first.major_radius, second.major_radius, "major radius", tol.length)
            )
            checks.append(
                ("radius", first.minor_radius, second.minor_radius, "minor radius", tol.length)
            )
        case Thread(), Thread():
            checks.append(("radius", first.radius, second.radius, "radius", tol.length))
            checks.append(("pitch", first.lead, second.lead, "lead", tol.length))
            if first.hand != second.hand:
                return EmptySet(
                    Mismatch("handedness", 2 * first.lead, f"hand {first.hand} vs {second.hand}"),
                    proven=True,
                )
        case Prism(), Prism():
            checks.append(("sides", first.sides, second.sides, "sides", 0.5))
            checks.append(("size", first.size, second.size, "size", tol.length))
    for kind, a, b, what, limit in checks:
        if abs(a - b) > limit:
            return _mismatch(kind, a, b, what)
    return None


def _fits_group(first: Feature, second: Feature) -> SymmetryGroup:
    """The common symmetry group on body 1's feature; the pair is directed only when both
    features are (an undirected hole takes a directed shaft either way round)."""
    if hasattr(second, "directed"):
        directed = second.directed and first.directed  # type: ignore[attr-defined]
        return replace(second, directed=directed).group()  # type: ignore[type-var]
    return second.group()


def relation_coset(
    kind: str,
    first: Feature,
    second: Feature,
    options: Mapping[str, Any] | None = None,
    tol: Tolerance | None = None,
) -> Coset | EmptySet:
    """The set of X = L_second⁻¹·L_first allowed by ``[kind, first, second]`` as a right
    coset H₁·x₀ in the second feature's body (ALGEBRA.md §3, §5.1), or an inconsistency.

    With F₁ = second.frame(), F₂ = first.frame():

    * ``against``: H₁ = G(n₁), x₀ = F₁·Tr(0,0,offset)·Rx(π)·F₂⁻¹ (normals opposed, a gap
      ``offset`` along n₁);
    * ``coplanar``: G(n₁)·F₁F₂⁻¹ (normals equal, planes coincide);
    * ``fits``: the common group (C, S, R, H, T⋊Cₙ; with the flip unless both features
      are directed) times F₁F₂⁻¹; unequal parameters give an :class:`EmptySet` whose
      :class:`Mismatch` kind is ``radius``, ``angle``, ``lead``, ``hand``, ``sides`` or
      ``size``, with the difference as value;
    * ``coaxial``: C(axis₁) (⋊ flip unless both directed) times F₁F₂⁻¹;
    * ``fixed``: {F₁F₂⁻¹};
    * ``parallel``: X(d₁)⋊⟨flip⟩ times F₁F₂⁻¹ (unoriented directions, 2 components);
    * ``coincident``: S(c₁)·Tr(c₁ − c₂).

    Raises :class:`FeatureError` for a kind that is not a coset or wrong feature types.
    """
    tol = tol or current()
    spec = _check(kind, first, second, None)
    if not spec.coset:
        raise FeatureError(f"{kind} is not a coset relation; use its residual")
    values = _option_values(kind, options or {}, None)
    f1, f2 = second.frame(), first.frame()
    aligned = f1 @ se3.inverse(f2)
    match kind:
        case "against":
            rep = f1 @ se3.translation((0.0, 0.0, values["offset"])) @ se3.rot_x(math.pi)
            return Coset(second.group(), rep @ se3.inverse(f2))
        case "coplanar":
            return Coset(second.group(), aligned)
        case "fits":
            return _fits_mismatch(first, second, tol) or Coset(_fits_group(first, second), aligned)
        case "coaxial":
            return Coset(_fits_group(_axis_of(first), _axis_of(second)), aligned)
        case "fixed":
            return Coset(SymmetryGroup.identity(), aligned)
        case "parallel":
            flip = f1 @ se3.rot_x(math.pi) @ se3.inverse(f1)
            group = SymmetryGroup.schoenflies(f1[:3, 2]).with_discrete(reps=(flip,))
            return Coset(group, aligned)
    centre1, centre2 = f1[:3, 3], f2[:3, 3]
    return Coset(SymmetryGroup.spherical(centre1), se3.translation(centre1 - centre2))


def _perpendicular_part(offset: NDArray[np.float64], axis: NDArray[np.float64]) -> NDArray:
    return offset - (offset @ axis) * axis


def _canonical_axis_residual(g: NDArray[np.float64], scale: float) -> NDArray[np.float64]:
    """Zero iff the canonical-frame motion g keeps the z-axis line with its direction."""
    return np.concatenate([(g[:3, 2] - (0.0, 0.0, 1.0)) * scale, g[:2, 3]])


def _discrete_residual(g: NDArray[np.float64], feature: Feature) -> NDArray[np.float64]:
    """The helical (thread) or cyclic (prism) part, as a length: zero iff the rotation
    angle θ about z of g satisfies θ ≡ t_z/p (mod 2π) for a thread of pitch p, or
    θ ≡ 0 (mod 2π/n) for an n-sided prism (ALGEBRA.md §2.3 membership, without a log)."""
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


def _parameter_residual(first: Feature, second: Feature) -> NDArray[np.float64]:
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


def _fits_residual(
    first: Feature, second: Feature, directed: bool, scale: float
) -> Callable[[NDArray[np.float64]], NDArray[np.float64]]:
    """Residual of ``fits`` (and ``coaxial``) on the pair of frames (G₂ = X·F₂, F₁)."""
    f1 = second.frame()
    inv_f1 = se3.inverse(f1)
    flip = se3.rot_x(math.pi)
    constant = _parameter_residual(first, second)
    spherical = isinstance(second, Ball | Socket)

    def canonical(g: NDArray[np.float64]) -> NDArray[np.float64]:
        if spherical:
            return g[:3, 3]
        parts = [_canonical_axis_residual(g, scale), _discrete_residual(g, second)]
        if isinstance(second, Cone | Torus):
            parts.append(g[2:3, 3])
        return np.concatenate(parts)

    def residual(moved: NDArray[np.float64]) -> NDArray[np.float64]:
        g = inv_f1 @ moved
        best = canonical(g)
        if not directed:
            other = canonical(g @ flip)
            best = other if float(other @ other) < float(best @ best) else best
        return np.concatenate([best, constant])

    return residual


def relation_residual(
    kind: str,
    first: Feature,
    second: Feature,
    options: Mapping[str, Any] | None = None,
    tol: Tolerance | None = None,
) -> Residual:
    """The residual r(X) of ``[kind, first, second]``: zero iff X = L_second⁻¹·L_first
    satisfies the relation (the coset of :func:`relation_coset` for coset kinds).

    Entries are lengths; direction terms are scaled by ``tol.arm`` (module docstring).
    The meaning of each non-coset kind: ``perpendicular`` d₂·d₁ = 0; ``angle`` d₂·d₁ =
    cos(angle); ``point_on_plane`` n·(c − p) = 0; ``point_on_line`` the offset of c from
    the line is 0; ``distance`` ‖c₂ − c₁‖ = d (points), n·(c − p) = d (point and plane,
    signed along the normal), the line parallel to the plane with n·(o − p) = d (a line
    and a plane: a cylinder of radius d lying on the plane, ALGEBRA.md §3), planes
    parallel with n₁·(p₂ − p₁) = d (two planes). Here d
    is a normal or axis, c a feature's point (centre, apex), p a plane point. Coupled
    kinds (``gear``, ``rack``, ``mirror``) raise :class:`FeatureError`: they are defined on the
    network (``assemblykit.inference.numeric``).
    """
    tol = tol or current()
    _check(kind, first, second, None)
    values = _option_values(kind, options or {}, None)
    if kind in COUPLED:
        raise FeatureError(f"{kind} couples motions through the network; it has no pair residual")
    arm = tol.arm
    f1, f2 = second.frame(), first.frame()
    d1, o1 = f1[:3, 2], f1[:3, 3]
    fits: Callable[[NDArray[np.float64]], NDArray[np.float64]] | None = None
    if kind in ("fits", "coaxial"):
        pair = (first, second) if kind == "fits" else (_axis_of(first), _axis_of(second))
        directed = _is_directed(pair[0]) and _is_directed(pair[1])
        fits = _fits_residual(pair[0], pair[1], directed, arm)

    def residual(x: NDArray[np.float64]) -> NDArray[np.float64]:
        moved = np.asarray(x, dtype=np.float64) @ f2
        d2, o2 = moved[:3, 2], moved[:3, 3]
        match kind:
            case "against":
                return np.append((d2 + d1) * arm, d1 @ (o2 - o1) - values["offset"])
            case "coplanar":
                return np.append((d2 - d1) * arm, d1 @ (o2 - o1))
            case "fits" | "coaxial":
                assert fits is not None
                return fits(moved)
            case "fixed":
                return np.concatenate([(moved[:3, :3] - f1[:3, :3]).ravel() * arm, o2 - o1])
            case "parallel":
                return np.cross(d2, d1) * arm
            case "perpendicular":
                return np.array([d2 @ d1 * arm])
            case "angle":
                return np.array([(d2 @ d1 - math.cos(values["angle"])) * arm])
            case "coincident":
                return o2 - o1
            case "point_on_plane":
                plane_d, plane_o, point = (
                    (d1, o1, o2) if isinstance(second, Plane) else (d2, o2, o1)
                )
                return np.array([plane_d @ (point - plane_o)])
            case "point_on_line":
                line_d, line_o, point = (d1, o1, o2) if second.type_name in AXIAL else (d2, o2, o1)
                return _perpendicular_part(point - line_o, line_d)
        distance = values["distance"]
        if isinstance(first, Plane) and isinstance(second, Plane):
            return np.append(np.cross(d2, d1) * arm, d1 @ (o2 - o1) - distance)
        if isinstance(second, Plane) and first.type_name in LINED:
            return np.array([d2 @ d1 * arm, d1 @ (o2 - o1) - distance])
        if isinstance(first, Plane) and second.type_name in LINED:
            return np.array([d1 @ d2 * arm, d2 @ (o1 - o2) - distance])
        if isinstance(second, Plane):
            return np.array([d1 @ (o2 - o1) - distance])
        if isinstance(first, Plane):
            return np.array([d2 @ (o1 - o2) - distance])
        return np.array([np.linalg.norm(o2 - o1) - distance])

    return residual


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
_DOF = {
    "against": 3,
    "coplanar": 3,
    "coaxial": 4,
    "fixed": 6,
    "parallel": 2,
    "perpendicular": 1,
    "angle": 1,
    "coincident": 3,
    "point_on_plane": 1,
    "point_on_line": 2,
}


def relation_dof_removed(kind: str, first: Feature, second: Feature) -> int:
    """The generic number of dof ``[kind, first, second]`` removes from X: 6 minus the dof
    of its coset for coset kinds (fits: C 4, S 3, R 5, H 5, T⋊Cₙ 5), and the number of
    independent scalar equations otherwise (distance: 1, 2 between a line and a plane,
    3 between two planes)."""
    _check(kind, first, second, None)
    if kind in COUPLED:
        raise FeatureError(f"{kind} couples motions through the network; it has no pair dof")
    if kind == "fits":
        return _FITS_DOF[second.type_name]
    if kind == "distance":
        if isinstance(first, Plane) and isinstance(second, Plane):
            return 3
        return 2 if LINED & {first.type_name, second.type_name} else 1
    return _DOF[kind]
