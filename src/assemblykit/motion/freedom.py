"""Motion of a part or subassembly relative to the rest of an assembly (Liu 1997).

Liu 1997 eq. (2): under surface contacts the relative position of a moving set S is
``l₁⁻¹l₂ ∈ f₁ G f₂⁻¹`` where G is the symmetry group of the *compound feature* formed by
all the oriented surfaces of S that touch the rest. G tells the motion: the identity
(fixed), a finite group (finitely many equivalent positions) or a continuous group of
dimension n (n degrees of freedom), with its invariants (axis, direction, point).

Every contact patch between S and the rest becomes one oriented primitive feature of
the moving side (Liu 1997 Def. 2.1.2: the surface with S's outward normals): a planar
patch a :class:`Plane` with the patch normal pointing out of S, a cylindrical patch a
:class:`Shaft` (S inside) or :class:`Hole`, a spherical one a :class:`Ball` or
:class:`Socket`, a conical one a :class:`Cone`. Repeated surfaces (coplanar patches,
one cylinder split in several patches) are one feature. The group is
:func:`assemblykit.features.compound_group` (Liu 1997 Props 3.2.6-3.2.8, 5.0.9).

Next to this *bilateral* reading (contacts are fits), every motion carries the
*unilateral* reading of :mod:`assemblykit.motion.unilateral` (faces only push): whether
the set can lift off, and along which directions.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from assemblykit.algebra import Kind, SymmetryGroup, intersect_groups, se3
from assemblykit.errors import UnknownNameError
from assemblykit.features import compound_group
from assemblykit.features.primitives import Ball, Cone, Feature, Hole, Plane, Shaft, Socket
from assemblykit.geometry.contact_values import Contact, CurvedPatch
from assemblykit.geometry.contacts import assembly_contacts
from assemblykit.model.assembly import Assembly
from assemblykit.motion.unilateral import UnilateralReading, unilateral_readings
from assemblykit.tolerance import ModelTolerance, Tolerance

Vector = NDArray[np.float64]
ContactFeature = Plane | Ball | Socket | Shaft | Hole | Cone
"""The oriented primitive features a contact patch becomes (Liu 1997 Def. 2.1.2)."""


def subassembly_key(names: Iterable[str]) -> str:
    """The report key of a moving set: its part names joined by ``+``."""
    return "+".join(names)


@dataclass(frozen=True, eq=False)
class ContactSamples:
    """Points on the contact surfaces of a moving set, with unit normals pointing out of
    the set into the obstacle (the rows of the unilateral linear program)."""

    points: NDArray[np.float64]
    normals: NDArray[np.float64]


def _curved_samples(patch: CurvedPatch, inside: bool) -> tuple[NDArray, NDArray]:
    """Points and normals out of the moving side sampling a curved patch where the two
    parts really touch (:meth:`CurvedPatch.samples`): a ball is pushed only where its
    socket is, a rod only where its groove is."""
    points, normals = patch.samples()
    return points, normals if inside else -normals


def _patch_feature(patch: CurvedPatch, inside: bool) -> ContactFeature:
    """The oriented primitive feature of the moving side of a curved patch."""
    if patch.kind == "spherical":
        return (Ball if inside else Socket)(point=patch.center, radius=patch.radius)
    assert patch.axis is not None
    if patch.kind == "cylindrical":
        cls = Shaft if inside else Hole
        return cls(point=patch.center, axis=patch.axis, radius=patch.radius, directed=False)
    return Cone(point=patch.center, axis=patch.axis, half_angle=patch.half_angle, male=inside)


def _same_feature(f: ContactFeature, g: ContactFeature, tol: ModelTolerance) -> bool:
    """Whether two features are the same oriented surface (so one is kept)."""
    if type(f) is not type(g):
        return False
    if isinstance(f, Plane) and isinstance(g, Plane):
        return bool(
            np.linalg.norm(f.normal - g.normal) <= tol.angle
            and abs(float(f.normal @ (g.point - f.point))) <= tol.length
        )
    if isinstance(f, Ball | Socket) and isinstance(g, Ball | Socket):
        return bool(
            np.linalg.norm(f.point - g.point) <= tol.length
            and abs(f.radius - g.radius) <= tol.length
        )
    assert isinstance(f, Shaft | Hole | Cone) and isinstance(g, Shaft | Hole | Cone)
    parallel = np.linalg.norm(np.cross(f.axis, g.axis)) <= tol.angle
    if isinstance(f, Cone) or isinstance(g, Cone):
        same_apex = np.linalg.norm(f.point - g.point) <= tol.length
        return bool(same_apex and f.axis @ g.axis > 0 and parallel)
    on_line = np.linalg.norm(np.cross(g.point - f.point, f.axis)) <= tol.length
    return bool(on_line and parallel and abs(f.radius - g.radius) <= tol.length)


def _distinct(
    features: Iterable[ContactFeature], tol: ModelTolerance
) -> tuple[ContactFeature, ...]:
    kept: list[ContactFeature] = []
    for feature in features:
        if not any(_same_feature(feature, k, tol) for k in kept):
            kept.append(feature)
    return tuple(kept)


def boundary_contacts(contacts: Iterable[Contact], moving: frozenset[str]) -> list[Contact]:
    """The contacts between the moving set and the rest."""
    return [c for c in contacts if (c.a in moving) != (c.b in moving)]


def moving_features(
    contacts: Iterable[Contact], moving: frozenset[str], tol: ModelTolerance
) -> tuple[tuple[ContactFeature, ...], ContactSamples]:
    """The compound feature of ``moving`` (its oriented contact surfaces, Liu 1997
    Def. 3.0.1) and the sampled contact points with normals out of ``moving``; contacts
    inside ``moving`` or inside the rest are skipped."""
    features: list[ContactFeature] = []
    points: list[NDArray] = []
    normals: list[NDArray] = []
    for contact in boundary_contacts(contacts, moving):
        sign = 1.0 if contact.a in moving else -1.0
        for planar in contact.planar:
            normal = sign * se3.unit(np.asarray(planar.normal, dtype=np.float64))
            features.append(Plane(point=planar.centroid, normal=normal))
            points.append(np.asarray(planar.polygon, dtype=np.float64))
            normals.append(np.tile(normal, (len(planar.polygon), 1)))
        for curved in contact.curved:
            inside = curved.inner in moving
            features.append(_patch_feature(curved, inside))
            sample_points, sample_normals = _curved_samples(curved, inside)
            points.append(sample_points)
            normals.append(sample_normals)
    samples = ContactSamples(
        np.vstack(points) if points else np.zeros((0, 3)),
        np.vstack(normals) if normals else np.zeros((0, 3)),
    )
    return _distinct(features, tol), samples


def _canonical_direction(u: Vector) -> Vector:
    """``u`` or ``-u``, whichever has its largest component positive (a line's direction
    is reported the same way whatever orientation the computation produced)."""
    u = np.asarray(u, dtype=np.float64)
    return u if u[int(np.argmax(np.abs(u)))] > 0 else -u


def motion_summary(group: SymmetryGroup | None) -> dict[str, Any]:
    """``motion`` (the group's kind), ``dof``, ``components`` (``"inf"`` for a lattice),
    ``description`` and the invariants as plain lists: ``axis`` {point, direction} with
    the point the axis' foot from the origin, ``center``, ``direction``, ``normal``,
    ``pitch``. ``None`` (no contact at all) is every rigid motion."""
    if group is None:
        return {"motion": "free", "dof": 6, "components": 1, "description": "free"}
    components = group.n_components
    out: dict[str, Any] = {
        "motion": str(group.kind),
        "dof": group.dof,
        "components": int(components) if math.isfinite(components) else "inf",
        "description": group.describe(),
    }
    inv = group.invariants
    if "axis" in inv:
        u = _canonical_direction(inv["axis"])
        foot = inv["point"] - (inv["point"] @ u) * u
        out["axis"] = {"point": foot.tolist(), "direction": u.tolist()}
    elif "point" in inv:
        out["center"] = np.asarray(inv["point"], dtype=np.float64).tolist()
    for key in ("direction", "normal"):
        if key in inv:
            out[key] = _canonical_direction(inv[key]).tolist()
    if "pitch" in inv:
        out["pitch"] = float(inv["pitch"])
    return out


class GroupMotion:
    """The name and dimension of a motion given by its ``group`` (``None``: every rigid
    motion), as :func:`motion_summary` reports them."""

    group: SymmetryGroup | None

    @property
    def kind(self) -> str:
        """The motion's name: ``fixed``, ``revolute``, ``prismatic``, ... or ``free``."""
        return str(motion_summary(self.group)["motion"])

    @property
    def dof(self) -> int:
        """Degrees of freedom of the motion (the group's dimension; for a set of parts,
        of the bilateral motion)."""
        return int(motion_summary(self.group)["dof"])


@dataclass(frozen=True, eq=False)
class Motion(GroupMotion):
    """The motion of a moving set of parts relative to the rest of its assembly.

    ``group``: the symmetry group of the compound feature of its contact surfaces (Liu
    1997 eq. (2)), ``None`` when it touches nothing; ``features``: that compound feature;
    ``touching``: the parts of the rest it touches; ``unilateral``: the push-only reading.
    """

    parts: tuple[str, ...]
    group: SymmetryGroup | None
    features: tuple[ContactFeature, ...]
    touching: tuple[str, ...]
    unilateral: UnilateralReading

    @property
    def key(self) -> str:
        """The report key: the part name, or ``a+b`` for a subassembly."""
        return subassembly_key(self.parts)

    def __repr__(self) -> str:
        from assemblykit import formatting as fmt

        return fmt.summary("Motion", self.key, self.kind, f"{self.dof} dof")

    @property
    def separates(self) -> bool:
        """Whether the bilateral motion carries the set arbitrarily far away: its group
        is continuous and not only rotations about a line or a point."""
        return self.kind not in (Kind.FIXED, Kind.REVOLUTE, Kind.SPHERICAL) and self.dof > 0

    def to_dict(self) -> dict[str, Any]:
        """``dof``, ``motion``, ``components``, the invariants (``axis`` {point,
        direction}, ``direction``, ``center``, ``normal``, ``pitch`` as they apply),
        ``touching`` and ``unilateral`` (docs/motion.md, "Contacts are fits")."""
        out = motion_summary(self.group)
        out["touching"] = list(self.touching)
        out["unilateral"] = self.unilateral.to_dict()
        return out


def _feature_key(feature: ContactFeature, anchor: Vector, tol: ModelTolerance) -> tuple[Any, ...]:
    """The feature seen from ``anchor``, rounded to the tolerance: equal keys mean the
    same oriented surface up to the translation between the anchors."""

    def lengths(x: Any) -> tuple[int, ...]:
        return tuple(np.rint(np.atleast_1d(x) / tol.length).astype(np.int64).tolist())

    def angles(x: Any) -> tuple[int, ...]:
        return tuple(np.rint(np.atleast_1d(x) / tol.angle).astype(np.int64).tolist())

    if isinstance(feature, Plane):
        return ("plane", angles(feature.normal), lengths(feature.normal @ (feature.point - anchor)))
    if isinstance(feature, Ball | Socket):
        return (feature.type_name, lengths(feature.point - anchor), lengths(feature.radius))
    offset = feature.point - anchor
    if isinstance(feature, Cone):
        return (
            "cone",
            lengths(offset),
            angles(feature.axis),
            angles(feature.half_angle),
            feature.male,
        )
    foot = offset - (offset @ feature.axis) * feature.axis
    return (feature.type_name, lengths(foot), angles(feature.axis), lengths(feature.radius))


class MotionSolver:
    """Motions of moving sets of one assembly, sharing its contacts and a cache of
    compound-feature groups.

    Congruent compound features have conjugate groups (docs/algebra.md §6, equivariance:
    moving the features by g maps G to g G g⁻¹), so a compound feature that is a
    translate of one already solved (keys of :func:`_feature_key` seen from the lower
    corner of the moving set's bounding box) gets that group conjugated by the
    translation, instead of a new permutation search (Liu 1997 Props 3.2.6-5.0.9).
    """

    def __init__(self, assembly: Assembly, tol: Tolerance | None = None) -> None:
        self.assembly = assembly
        self.tol = assembly.tolerance(tol)
        self.contacts = assembly_contacts(assembly, tol)
        self._groups: dict[tuple[Any, ...], tuple[SymmetryGroup, Vector]] = {}
        self._by_part: dict[str, list[Contact]] = {}
        for contact in self.contacts:
            self._by_part.setdefault(contact.a, []).append(contact)
            self._by_part.setdefault(contact.b, []).append(contact)

    def group(self, features: Sequence[ContactFeature], anchor: Vector) -> SymmetryGroup:
        """The symmetry group of the compound feature (Liu 1997 Props 3.2.6-3.2.8, 5.0.9)."""
        key = tuple(sorted(_feature_key(f, anchor, self.tol) for f in features))
        if key not in self._groups:
            self._groups[key] = (compound_group(features, self.tol), anchor)
            return self._groups[key][0]
        group, seen_at = self._groups[key]
        return group.conjugate(se3.translation(anchor - seen_at))

    def connected_group(self, features: Sequence[Feature]) -> SymmetryGroup:
        """The identity component of the compound feature's group: the swaps of
        2-congruent features only add discrete components (Liu 1997 Props 3.2.8,
        5.0.9), so it is the identity component of G₁ ∩ ... ∩ Gₙ (Prop 3.2.6)."""
        groups = [f.group().connected_part for f in features]
        return functools.reduce(lambda g, h: intersect_groups(g, h, tol=self.tol), groups)

    def boundary(self, members: frozenset[str]) -> list[Contact]:
        """The contacts between ``members`` and the rest (through a per-part index)."""
        return [
            c
            for n in members
            for c in self._by_part.get(n, ())
            if (c.a in members) != (c.b in members)
        ]

    def motions_of(
        self, sets: Iterable[str | Sequence[str]], components: bool = True
    ) -> list[Motion]:
        """The motion of each moving set: one part (a name) or a subassembly (names),
        relative to the rest. With ``components`` false only the group's identity
        component is computed (its kind, dof and invariants; one component), which is
        much faster. The unilateral readings are solved together (one linear program)."""
        prepared = []
        for names in sets:
            moving = (names,) if isinstance(names, str) else tuple(dict.fromkeys(names))
            if not moving:
                raise UnknownNameError(
                    "a moving set needs at least one part", source=self.assembly.source
                )
            parts = [self.assembly.part(name) for name in moving]
            members = frozenset(moving)
            boundary = self.boundary(members)
            features, samples = moving_features(boundary, members, self.tol)
            touching = tuple(sorted({c.b if c.a in members else c.a for c in boundary}))
            anchor = np.min([p.mesh.bounds[0] for p in parts], axis=0)
            if not features:
                group = None
            elif components:
                group = self.group(features, anchor)
            else:
                group = self.connected_group(features)
            prepared.append((moving, group, features, touching, samples))
        readings = unilateral_readings(
            [(p[4].points, p[4].normals) for p in prepared], self.assembly.scale, self.tol
        )
        return [
            Motion(moving, group, features, touching, reading)
            for (moving, group, features, touching, _), reading in zip(
                prepared, readings, strict=True
            )
        ]

    def motion_of(self, names: str | Sequence[str], components: bool = True) -> Motion:
        """The motion of one part (a name) or a subassembly (names) relative to the rest
        (:meth:`motions_of`)."""
        return self.motions_of([names], components)[0]


def part_motion(
    assembly: Assembly, names: str | Sequence[str], tol: Tolerance | None = None
) -> Motion:
    """The motion of one part (a name) or a subassembly (names) relative to the rest."""
    return MotionSolver(assembly, tol).motion_of(names)


@dataclass(frozen=True, eq=False)
class MotionReport:
    """The motion of every part (and of the requested subassemblies) of an assembly."""

    motions: dict[str, Motion]
    source: str | None = None

    def __getitem__(self, key: str) -> Motion:
        return self.motions[key]

    def __contains__(self, key: object) -> bool:
        return key in self.motions

    def __iter__(self) -> Iterator[str]:
        """The part (and subassembly) names, as a mapping iterates."""
        return iter(self.motions)

    def __repr__(self) -> str:
        from assemblykit import formatting as fmt

        moving = sum(1 for m in self.motions.values() if m.dof > 0)
        return fmt.summary(
            "MotionReport",
            fmt.count(len(self.motions), "moving set"),
            f"{moving} with freedom",
            fmt.file_name(self.source),
        )

    def _repr_html_(self) -> str:
        """The motions as a table (notebooks)."""
        from assemblykit import formatting as fmt

        rows = [(k, m.kind, str(m.dof), ", ".join(m.touching)) for k, m in self.motions.items()]
        return fmt.html_summary(repr(self), ("part", "motion", "dof", "touching"), rows)

    def to_dict(self) -> dict[str, Any]:
        """``parts`` keyed by part name (subassemblies by ``a+b``), docs/motion.md,
        "Contacts are fits"."""
        return {"source": self.source, "parts": {k: m.to_dict() for k, m in self.motions.items()}}


def motion(
    assembly: Assembly,
    subassemblies: Iterable[Sequence[str]] | None = None,
    tol: Tolerance | None = None,
) -> MotionReport:
    """How each part, and each given subassembly, can still move relative to the rest of
    ``assembly``: the symmetry group of the compound feature its contacts form (Liu 1997
    eq. (2); docs/motion.md, "Contacts are fits"), and which way it can lift off
    (docs/motion.md, "Faces only push").

    Parameters
    ----------
    assembly : Assembly
        The parts in assembled position (:func:`assemblykit.load_assembly`).
    subassemblies : iterable of sequences of str, optional
        Sets of parts that move together, each reported under its names joined by
        ``+``, after the single parts.
    tol : Tolerance, optional
        The tolerance policy (the assembly's own when ``None``).

    Returns
    -------
    MotionReport
        One :class:`Motion` per moving set, by name: its kind (``fixed``, ``revolute``,
        ``prismatic``, ...), dof, invariants and the parts it touches.

    Raises
    ------
    UnknownNameError
        A subassembly names a part the assembly does not have, or no part at all.

    Examples
    --------
    >>> from pathlib import Path
    >>> import assemblykit
    >>> examples = Path(assemblykit.__file__).parent / "examples"
    >>> hinge = assemblykit.load_assembly(examples / "motion" / "hinge" / "hinge.yaml")
    >>> report = assemblykit.motion(hinge, [["frame", "door"]])
    >>> report
    MotionReport(3 moving sets, 3 with freedom, hinge.yaml)
    >>> report["door"], report["frame+door"].kind
    (Motion(door, revolute, 1 dof), 'free')
    """
    solver = MotionSolver(assembly, tol)
    sets: list[Sequence[str]] = [(name,) for name in assembly.names]
    sets.extend(subassemblies or ())
    motions = solver.motions_of(sets)
    return MotionReport({m.key: m for m in motions}, assembly.source)
