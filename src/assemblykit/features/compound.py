"""Pairwise relationships of oriented features and compound-feature symmetry groups.

Liu 1997 §3: a compound feature is a set of oriented primitive features (Def. 3.0.1);
its symmetry group is the intersection of the primitive groups (Props 3.2.6, 3.2.7)
enlarged by the isometries that swap congruent features (Props 3.2.8, 5.0.9). It is
computed here by the permutation method of docs/algebra.md §4.1, which covers all of them:
the union, over the class-preserving permutations π, of the non-empty transporters
{g : g(Fᵢ) = F_π(i) for all i}.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, replace
from enum import Enum

import numpy as np
from numpy.typing import NDArray

from assemblykit.algebra import Coset, EmptySet, SymmetryGroup, intersect_groups, se3
from assemblykit.errors import FeatureError
from assemblykit.features.primitives import (
    Ball,
    Cone,
    Feature,
    Frame,
    Hole,
    Plane,
    Prism,
    Shaft,
    Socket,
    Thread,
    Torus,
)
from assemblykit.tolerance import Tolerance, current


class Relationship(Enum):
    """The four relationships of a pair of oriented primitive features (Liu 1997 Def. 3.1.2)."""

    DISTINCT = "distinct"
    ONE_CONGRUENT = "1-congruent"
    TWO_CONGRUENT = "2-congruent"
    COMPLEMENTARY = "complementary"


@dataclass(frozen=True)
class _Shape:
    """What congruence compares: the surface family, its parameters and its material side.

    ``lengths`` compare within the length tolerance, ``angles`` within the angle
    tolerance, ``counts`` exactly; ``outward`` is the material side (shaft vs hole)."""

    family: str
    lengths: tuple[float, ...] = ()
    angles: tuple[float, ...] = ()
    counts: tuple[int, ...] = ()
    outward: bool = True


def _shape(feature: Feature) -> _Shape:
    """The congruence data of a feature (its canonical surface up to a rigid motion)."""
    match feature:
        case Shaft() | Hole():
            return _Shape("cylinder", (feature.radius,), outward=isinstance(feature, Shaft))
        case Ball() | Socket():
            return _Shape("sphere", (feature.radius,), outward=isinstance(feature, Ball))
        case Cone():
            return _Shape("cone", angles=(feature.half_angle,), outward=feature.male)
        case Torus():
            lengths = (feature.major_radius, feature.minor_radius)
            return _Shape("torus", lengths, outward=feature.male)
        case Thread():
            return _Shape("thread", (feature.radius, feature.pitch), outward=feature.male)
        case Prism():
            return _Shape("prism", (feature.size,), counts=(feature.sides,), outward=feature.male)
        case _:
            return _Shape(feature.type_name)


def _same_surface(a: _Shape, b: _Shape, tol: Tolerance) -> bool:
    """Whether two shapes have the same family and parameters (sides ignored)."""
    return (
        a.family == b.family
        and a.counts == b.counts
        and all(abs(x - y) <= tol.length for x, y in zip(a.lengths, b.lengths, strict=True))
        and all(abs(x - y) <= tol.angle for x, y in zip(a.angles, b.angles, strict=True))
    )


def _directed(feature: Feature) -> bool:
    return bool(getattr(feature, "directed", False))


def _common_orientation(f1: Feature, f2: Feature) -> tuple[Feature, Feature]:
    """Both features with the axis orientation both of them declare.

    ``directed`` is a modelling attribute of an axis, not part of the surface; when only
    one feature declares it, the pair is judged as undirected (docs/algebra.md §7)."""
    if hasattr(f1, "directed") and _directed(f1) != _directed(f2):
        return replace(f1, directed=False), replace(f2, directed=False)  # type: ignore[type-var]
    return f1, f2


def feature_transporter(source: Feature, target: Feature) -> Coset:
    """{g : g(source) = target} for two features with the same canonical surface:
    ``target.group() · F_target·F_source⁻¹`` (docs/algebra.md §4.1 step 2, §3)."""
    return Coset(target.group(), target.frame() @ se3.inverse(source.frame()))


def _swap_exists(f1: Feature, f2: Feature, tol: Tolerance) -> bool:
    """Whether some proper motion maps f1 onto f2 *and* f2 onto f1 (Liu 1997 Def. 3.1.2).

    Closed forms (each a half-turn, derived from the invariants of docs/algebra.md §2.4):

    * two oriented planes: always, except parallel planes with equal normals and a
      non-zero offset (Liu's (1997) 1-congruent example); the half-turn is about the
      bisector of the normals through the planes' common line (or mid-plane);
    * two points, two lines (directed or not), two spheres, two cylinders: always; the
      half-turn is about the bisector of the directions through the midpoint of the
      common perpendicular;
    * two cones (directed line with its apex a marked): iff (a₂ − a₁)·(u₁ + u₂) = 0;
    * two tori (undirected line, marked centre c): iff (c₂ − c₁)·(u₁ ± u₂) = 0 for a sign;
    * threads, prisms and frames (discrete parts): the two transporters intersect.
    """
    match f1, f2:
        case Plane(), Plane():
            same = float(f1.normal @ f2.normal) >= math.cos(tol.angle)
            return not same or abs(float(f1.normal @ (f2.point - f1.point))) <= tol.length
        case Cone(), Cone():
            return abs(float((f2.point - f1.point) @ (f1.axis + f2.axis))) <= tol.length
        case Torus(), Torus():
            offset = f2.point - f1.point
            return (
                min(
                    abs(float(offset @ (f1.axis + f2.axis))),
                    abs(float(offset @ (f1.axis - f2.axis))),
                )
                <= tol.length
            )
        case (Thread(), Thread()) | (Prism(), Prism()) | (Frame(), Frame()):
            both = feature_transporter(f1, f2).intersect(feature_transporter(f2, f1), tol=tol)
            return not isinstance(both, EmptySet)
        case _:
            return True


def relationship(f1: Feature, f2: Feature, tol: Tolerance | None = None) -> Relationship:
    """The relationship of two oriented primitive features (Liu 1997 Def. 3.1.2).

    Reading of the definition used here:

    * **distinct**: the canonical surfaces differ (another family, or other radii,
      half-angle, lead/hand, sides or size): no open patch of one maps into the other;
    * **complementary**: the same surface with the opposite material side (shaft/hole,
      ball/socket, male/female cone, torus, thread, prism), g(S₁) = S₂ with g*ρ₁ = −ρ₂;
    * same surface and same side: **2-congruent** if a motion swaps the two features
      (see :func:`_swap_exists`), else **1-congruent**.

    Planes: any two oriented planes are complementary *and* 1- or 2-congruent at once
    (Liu 1997 Cor. 3.1.4 and the remark after it). Since complementarity carries no
    information for planes, their congruence is returned. Datum points, axes and frames
    have no material side and are never complementary. Props 3.1.3 (exhaustiveness) and
    3.1.5 (complementary features have conjugate groups aG₁a⁻¹ = G₂) hold by construction.
    """
    tol = tol or current()
    s1, s2 = _shape(f1), _shape(f2)
    if not _same_surface(s1, s2, tol):
        return Relationship.DISTINCT
    if s1.outward != s2.outward:
        return Relationship.COMPLEMENTARY
    f1, f2 = _common_orientation(f1, f2)
    return Relationship.TWO_CONGRUENT if _swap_exists(f1, f2, tol) else Relationship.ONE_CONGRUENT


def _congruence_classes(features: Sequence[Feature], tol: Tolerance) -> list[int]:
    """A class index per feature: same surface, same side and same ``directed`` flag
    (docs/algebra.md §4.1 step 1)."""
    shapes = [(_shape(f), _directed(f)) for f in features]
    classes: list[int] = []
    for i, (shape, directed) in enumerate(shapes):
        match = next(
            (
                classes[j]
                for j in range(i)
                if shapes[j][1] == directed
                and shapes[j][0].outward == shape.outward
                and _same_surface(shapes[j][0], shape, tol)
            ),
            i,
        )
        classes.append(match)
    return classes


def _plane_invariants(features: Sequence[Feature], tol: Tolerance) -> tuple[NDArray, NDArray]:
    """Rigid-motion invariants of every pair of planes (NaN where a feature is not a
    plane): the cosine of the angle of their normals, and for parallel or antiparallel
    planes the signed offset nᵢ·(pⱼ − pᵢ). A motion mapping Fᵢ, Fⱼ onto F_π(i), F_π(j)
    keeps both, so a permutation that changes them has an empty transporter."""
    n = len(features)
    normals = np.full((n, 3), np.nan)
    points = np.full((n, 3), np.nan)
    for i, f in enumerate(features):
        if isinstance(f, Plane):
            normals[i], points[i] = f.normal, f.point
    cosines = normals @ normals.T
    offsets = np.einsum("ik,ijk->ij", normals, points[None, :, :] - points[:, None, :])
    offsets[~(np.abs(cosines) >= math.cos(tol.angle))] = np.nan
    return cosines, offsets


def _differ(a: NDArray, b: NDArray, limit: float) -> bool:
    """Whether two invariant vectors differ by more than ``limit`` where both are known."""
    known = ~(np.isnan(a) | np.isnan(b))
    return bool(np.any(np.abs(a[known] - b[known]) > limit))


def _transporters(
    features: Sequence[Feature], classes: Sequence[int], tol: Tolerance
) -> Iterable[tuple[tuple[int, ...], Coset]]:
    """The non-empty cosets {g : g(Fᵢ) = F_π(i) ∀i} over class-preserving permutations π,
    each with its π.

    Depth-first over the assignments π(0), π(1), ...; an empty partial intersection
    prunes every permutation that extends it (docs/algebra.md §4.1 steps 2-3). Before
    intersecting, an assignment that changes a pairwise plane invariant
    (:func:`_plane_invariants`) with an earlier one is pruned at once: its intersection
    would be empty, and the invariants cost a comparison where the intersection costs
    a transporter. Once the partial coset is a single motion, each further step is a
    membership test of that motion."""
    cosines, offsets = _plane_invariants(features, tol)

    def extend(
        index: int, assigned: tuple[int, ...], partial: Coset | None
    ) -> Iterable[tuple[tuple[int, ...], Coset]]:
        if index == len(features):
            assert partial is not None
            yield assigned, partial
            return
        for target in range(len(features)):
            if target in assigned or classes[target] != classes[index]:
                continue
            images = list(assigned)
            if _differ(cosines[index, :index], cosines[target, images], tol.angle) or _differ(
                offsets[index, :index], offsets[target, images], tol.length
            ):
                continue
            step = feature_transporter(features[index], features[target])
            if partial is not None and partial.is_point:
                # a single motion: the intersection is it or nothing, a membership test
                if step.contains(partial.rep, tol):
                    yield from extend(index + 1, (*assigned, target), partial)
                continue
            both = step if partial is None else partial.intersect(step, tol=tol)
            if not isinstance(both, EmptySet):
                yield from extend(index + 1, (*assigned, target), both)

    return extend(0, (), None)


def compound_group(features: Sequence[Feature], tol: Tolerance | None = None) -> SymmetryGroup:
    """The symmetry group of a compound feature (Liu 1997 Props 3.2.6-3.2.8, 5.0.9).

    docs/algebra.md §4.1: the union of the non-empty transporters over class-preserving
    permutations. The identity permutation gives G₁ ∩ ... ∩ Gₙ (Props 3.2.6, 3.2.7),
    computed as the meet of the groups (it always holds the identity, also for axes
    just beyond the angle tolerance of parallel, where a meet of cosets may find no
    common point); the others add the swaps g_ij of 2-congruent features and their
    products (Props 3.2.8, 5.0.9), each a coset of that intersection. When no two
    features are the same surface, these cosets are disjoint and already form the group,
    so their components are listed directly instead of closing them again under
    composition.
    """
    tol = tol or current()
    if not features:
        raise FeatureError("a compound feature needs at least one primitive feature")
    identity_order = tuple(range(len(features)))
    cosets = [
        coset
        for order, coset in _transporters(features, _congruence_classes(features, tol), tol)
        if order != identity_order
    ]
    base = functools.reduce(
        lambda group, feature: intersect_groups(group, feature.group(), tol),
        features[1:],
        features[0].group(),
    )
    swaps = [coset.rep for coset in cosets]
    if not swaps:
        return base
    identity = np.eye(4)
    if base.lattice or any(coset.contains(identity, tol) for coset in cosets):
        return base.extended_by(swaps, tol=tol)
    # Pairwise distinct features: the transporters of distinct permutations are
    # disjoint, and together they are the whole group, closed already; each is
    # base · swap, whose components are r · swap for the components r of base.
    reps = (*base.reps, *(r @ swap for swap in swaps for r in base.reps))
    return SymmetryGroup(base.kind, base.frame, base.pitch, reps)


@dataclass(frozen=True, eq=False)
class CompoundFeature:
    """A named set of oriented primitive features of one body (Liu 1997 Def. 3.0.1)."""

    name: str
    features: tuple[Feature, ...]

    def __post_init__(self) -> None:
        object.__setattr__(self, "features", tuple(self.features))
        if not self.features:
            raise FeatureError("a compound feature needs at least one feature", where=self.name)

    def group(self, tol: Tolerance | None = None) -> SymmetryGroup:
        """Its symmetry group (:func:`compound_group`)."""
        return compound_group(self.features, tol)
