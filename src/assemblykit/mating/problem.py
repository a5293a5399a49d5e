"""The mating problem (seed 002, "Input"): bodies with features, compound features,
optional meshes and symmetry, and goals such as ``[fit, b1, b4]``.

File layout (YAML or JSON, validated with pydantic; features use the task-file YAML of
DESIGN.md §5.1)::

    units: mm
    bodies:
      b1:
        features: {bottom: {type: plane, point: [0, 0, -1], normal: [0, 0, -1]}, ...}
        compound: {comp1: [bottom, peg_a, peg_b]}   # default: one per primitive feature
        mesh: b1.obj                                # or {add: [...], cut: [...]} primitives
        symmetry: [{point: [0, 0, 0], axis: [0, 1, 0], angle: 180 deg}]   # or none
        sharable: [rim]                             # non-plane features several mates share
    goals:
      - [fit, b1, b4]

A generated ``mesh`` is the union of its ``add`` primitives minus its ``cut`` ones; a
primitive is ``{box: {min: [x, y, z], max: [x, y, z]}}`` or ``{cylinder: {point, axis,
radius, height}}`` (base centre, axis direction). Without ``symmetry`` the body's group
is computed from its features (seed 003 §3, the compound group of all of them), and its
discrete elements are kept only when they also map the mesh onto itself.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Annotated, Any, Literal

import manifold3d
import numpy as np
import trimesh
from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

from assemblykit.algebra import SymmetryGroup, se3
from assemblykit.errors import GeometryError, InputError, SchemaError, UnknownNameError
from assemblykit.features import CompoundFeature, Feature, Plane, feature_from_dict, parse_angle
from assemblykit.features.compound import compound_group
from assemblykit.geometry.interference import overlap_volume, solid
from assemblykit.io.meshes import placed, read_mesh
from assemblykit.io.spec import UNITS, Name, _schema_error, _with_source, read_json, read_yaml
from assemblykit.tolerance import Tolerance, current

Vector3 = tuple[float, float, float]

#: Sections of generated cylinders: enough that a facet's sagitta is under 0.5 % of r.
CYLINDER_SECTIONS = 48


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class BoxModel(_Model):
    """An axis-aligned box given by its ``min`` and ``max`` corners."""

    min: Vector3
    max: Vector3


class CylinderModel(_Model):
    """A cylinder: base centre ``point``, ``axis`` direction, ``radius`` and ``height``."""

    point: Vector3
    axis: Vector3
    radius: Annotated[float, Field(gt=0)]
    height: Annotated[float, Field(gt=0)]


class PrimitiveModel(_Model):
    """One solid primitive: exactly one of ``box`` or ``cylinder``."""

    box: BoxModel | None = None
    cylinder: CylinderModel | None = None

    @model_validator(mode="after")
    def _one_kind(self) -> PrimitiveModel:
        if (self.box is None) == (self.cylinder is None):
            raise ValueError("give exactly one of box or cylinder")
        return self


class ShapeModel(_Model):
    """A generated mesh: the union of ``add`` minus the union of ``cut``."""

    add: Annotated[list[PrimitiveModel], Field(min_length=1)]
    cut: list[PrimitiveModel] = Field(default_factory=list)


class RotationModel(_Model):
    """A symmetry element: the rotation by ``angle`` about the line (``point``, ``axis``)."""

    point: Vector3 = (0.0, 0.0, 0.0)
    axis: Vector3
    angle: float | str


class BodyModel(_Model):
    """``bodies.<name>``."""

    features: dict[Name, dict[str, Any]]
    compound: dict[Name, Annotated[list[Name], Field(min_length=1)]] = Field(default_factory=dict)
    mesh: str | ShapeModel | None = None
    symmetry: list[RotationModel] | Literal["none"] | None = None
    sharable: list[Name] = Field(default_factory=list)


class ProblemModel(_Model):
    """The whole problem file."""

    units: Literal[UNITS] = "mm"  # type: ignore[valid-type]
    bodies: dict[Name, BodyModel]
    goals: Annotated[list[tuple[Literal["fit"], Name, Name]], Field(min_length=1)]


@dataclass(frozen=True, eq=False)
class MatingBody:
    """A body of a mating problem: primitive ``features``, ``compounds`` (named sets of
    them), an optional closed ``mesh`` in body coordinates, its ``symmetry`` group and the
    names of its ``sharable`` features (seed 002 footnote 3: a third feature may mate)."""

    name: str
    features: Mapping[str, Feature]
    compounds: Mapping[str, CompoundFeature]
    members: Mapping[str, tuple[str, ...]]
    mesh: trimesh.Trimesh | None
    symmetry: SymmetryGroup
    sharable: frozenset[str]


@dataclass(frozen=True)
class Goal:
    """A required relationship between two bodies (seed 002: ``[goal i [fit b1 b4]]``);
    ``number`` counts from 1 as in the seed."""

    number: int
    relation: str
    first: str
    second: str

    def describe(self) -> str:
        """``goal 1 [fit b1 b4]``."""
        return f"goal {self.number} [{self.relation} {self.first} {self.second}]"


@dataclass(frozen=True, eq=False)
class MatingProblem:
    """Bodies and goals of an assembly constraint satisfaction problem (seed 002)."""

    units: str
    bodies: Mapping[str, MatingBody]
    goals: tuple[Goal, ...]
    source: str | None = None
    tolerance: Tolerance = field(default_factory=current)


def load_problem(path: str | Path, tol: Tolerance | None = None) -> MatingProblem:
    """Read and validate a mating problem (``.yaml``, ``.yml`` or ``.json``); mesh paths
    are relative to the file's folder. Errors name the file and the field path."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as error:
        raise InputError(f"cannot read the problem: {error.strerror}", source=str(path)) from None
    suffix = path.suffix.lower()
    if suffix in (".yaml", ".yml"):
        data = read_yaml(text, path.name)
    elif suffix == ".json":
        data = read_json(text, path.name)
    else:
        raise InputError(
            f"unknown problem file type {path.suffix!r} (expected .yaml, .yml or .json)",
            source=path.name,
        )
    return parse_problem(data, path.name, path.parent, tol)


def parse_problem(
    data: Any, source: str | None = None, folder: Path | None = None, tol: Tolerance | None = None
) -> MatingProblem:
    """Build a :class:`MatingProblem` from the file's mapping; the tolerance is scaled to
    the bounding-box diagonal of the feature points and meshes (DESIGN.md §4)."""
    if not isinstance(data, Mapping):
        raise SchemaError(
            "a mating problem must hold a mapping with bodies and goals", source=source
        )
    try:
        model = ProblemModel.model_validate(data)
    except ValidationError as error:
        raise _schema_error(error, source, lambda place: place) from None
    try:
        features = {
            name: {
                fname: feature_from_dict(fname, fdata, f"bodies.{name}.features.{fname}")
                for fname, fdata in body.features.items()
            }
            for name, body in model.bodies.items()
        }
        meshes = {
            name: _mesh(body.mesh, folder or Path("."), f"bodies.{name}.mesh")
            for name, body in model.bodies.items()
        }
        tol = (tol or current()).with_scale(_diagonal(features, meshes))
        bodies = {
            name: _body(name, body, features[name], meshes[name], tol)
            for name, body in model.bodies.items()
        }
        goals = tuple(_goal(i, items, bodies) for i, items in enumerate(model.goals))
    except InputError as error:
        raise _with_source(error, source) from None
    return MatingProblem(model.units, bodies, goals, source, tol)


def _goal(index: int, items: tuple[str, str, str], bodies: Mapping[str, MatingBody]) -> Goal:
    relation, first, second = items
    for position, name in ((1, first), (2, second)):
        if name not in bodies:
            raise UnknownNameError(f"no body named {name!r}", where=f"goals[{index}][{position}]")
    if first == second:
        raise SchemaError("a goal relates two different bodies", where=f"goals[{index}]")
    return Goal(index + 1, relation, first, second)


def _body(
    name: str,
    model: BodyModel,
    features: Mapping[str, Feature],
    mesh: trimesh.Trimesh | None,
    tol: Tolerance,
) -> MatingBody:
    place = f"bodies.{name}"
    members = dict(model.compound) or {fname: [fname] for fname in features}
    for cname, names in members.items():
        for index, fname in enumerate(names):
            if fname not in features:
                raise UnknownNameError(
                    f"no feature named {fname!r}", where=f"{place}.compound.{cname}[{index}]"
                )
    for index, fname in enumerate(model.sharable):
        if fname not in features:
            raise UnknownNameError(
                f"no feature named {fname!r}", where=f"{place}.sharable[{index}]"
            )
    compounds = {
        cname: CompoundFeature(cname, tuple(features[f] for f in names))
        for cname, names in members.items()
    }
    symmetry = _symmetry(model.symmetry, features, mesh, tol, f"{place}.symmetry")
    sharable = frozenset(model.sharable) | {f for f, v in features.items() if isinstance(v, Plane)}
    return MatingBody(
        name,
        features,
        compounds,
        {cname: tuple(names) for cname, names in members.items()},
        mesh,
        symmetry,
        frozenset(sharable),
    )


def _symmetry(
    spec: list[RotationModel] | Literal["none"] | None,
    features: Mapping[str, Feature],
    mesh: trimesh.Trimesh | None,
    tol: Tolerance,
    where: str,
) -> SymmetryGroup:
    """The body's symmetry group: explicit generators, ``none``, or the group of all its
    features with the discrete elements that do not preserve the mesh removed."""
    if spec == "none" or not features:
        return SymmetryGroup.identity()
    if isinstance(spec, list):
        elements = [
            se3.rotation(r.axis, parse_angle(r.angle, f"{where}[{i}].angle"), r.point)
            for i, r in enumerate(spec)
        ]
        return SymmetryGroup.identity().extended_by(elements, tol=tol)
    group = compound_group(tuple(features.values()), tol)
    if mesh is None:
        return group
    kept = [g for g in group.reps[1:] if _preserves(mesh, g, tol)]
    return SymmetryGroup.identity().extended_by(kept, tol=tol) if kept else SymmetryGroup.identity()


def _preserves(mesh: trimesh.Trimesh, g: np.ndarray, tol: Tolerance) -> bool:
    """Whether ``g`` maps the solid onto itself: vol(M ∩ gM) = vol(M) within the mesh
    tolerance over its surface."""
    shared = overlap_volume(mesh, placed(mesh, g))
    return abs(float(mesh.volume) - shared) <= tol.mesh_length * float(mesh.area)


def _diagonal(
    features: Mapping[str, Mapping[str, Feature]], meshes: Mapping[str, trimesh.Trimesh | None]
) -> float:
    points = [f.frame()[:3, 3] for body in features.values() for f in body.values()]
    points += [corner for m in meshes.values() if m is not None for corner in m.bounds]
    if len(points) < 2:
        return 1.0
    cloud = np.asarray(points)
    return float(np.linalg.norm(cloud.max(axis=0) - cloud.min(axis=0))) or 1.0


def _mesh(spec: str | ShapeModel | None, folder: Path, where: str) -> trimesh.Trimesh | None:
    if spec is None:
        return None
    if isinstance(spec, str):
        try:
            return read_mesh(folder / spec)
        except GeometryError as error:
            raise GeometryError(error.detail, where=f"{where} ({spec})") from None
    return generated_mesh(spec, where)


def generated_mesh(spec: ShapeModel, where: str | None = None) -> trimesh.Trimesh:
    """The closed mesh of ``add`` minus ``cut`` (manifold3d booleans)."""
    added = manifold3d.Manifold.batch_boolean(
        [_primitive(p) for p in spec.add], manifold3d.OpType.Add
    )
    if spec.cut:
        cut = manifold3d.Manifold.batch_boolean(
            [_primitive(p) for p in spec.cut], manifold3d.OpType.Add
        )
        added = added - cut
    out = added.to_mesh()
    mesh = trimesh.Trimesh(
        np.asarray(out.vert_properties[:, :3], dtype=np.float64),
        np.asarray(out.tri_verts, dtype=np.int64),
        process=True,
    )
    if mesh.is_empty:
        raise GeometryError("the generated mesh is empty", where=where)
    return mesh


def _primitive(spec: PrimitiveModel) -> manifold3d.Manifold:
    if spec.box is not None:
        lo, hi = np.asarray(spec.box.min), np.asarray(spec.box.max)
        if np.any(hi <= lo):
            raise SchemaError("a box needs max > min on every axis")
        return solid(trimesh.creation.box(bounds=np.stack([lo, hi])))
    assert spec.cylinder is not None
    c = spec.cylinder
    axis = np.asarray(c.axis, dtype=np.float64)
    if not math.isfinite(float(np.linalg.norm(axis))) or np.linalg.norm(axis) == 0:
        raise SchemaError("a cylinder axis must be a non-zero vector")
    start = np.asarray(c.point, dtype=np.float64)
    end = start + c.height * axis / np.linalg.norm(axis)
    shape = trimesh.creation.cylinder(
        radius=c.radius, segment=np.stack([start, end]), sections=CYLINDER_SECTIONS
    )
    return solid(shape)
