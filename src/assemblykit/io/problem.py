"""The mating problem file (Liu & Popplestone 1990, "Input"), read into a validated
:class:`~assemblykit.mating.problem.MatingProblem`.

File layout (YAML or JSON, validated with pydantic; features use the task-file YAML of
docs/tutorial.md §1)::

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

A generated ``mesh`` is the union of its ``add`` primitives minus its ``cut`` ones
(:mod:`assemblykit.geometry.solids`); a primitive is ``{box: {min: [x, y, z], max: [x,
y, z]}}`` or ``{cylinder: {point, axis, radius, height}}`` (base centre, axis
direction). Mesh paths are relative to the file's folder. Every error names the file and
the field path, e.g. ``p.yaml: goals[0][2]: no body named 'c'``.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
import trimesh
from pydantic import (
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    model_validator,
)

from assemblykit.algebra import se3
from assemblykit.errors import GeometryError, InputError, SchemaError, UnknownNameError
from assemblykit.features import Feature, feature_from_dict, parse_angle
from assemblykit.geometry.solids import Box, Cylinder, Primitive, generated_mesh
from assemblykit.io.documents import read_json, read_text, read_yaml
from assemblykit.io.meshes import read_mesh
from assemblykit.io.spec import UNITS, Name, validated, with_source
from assemblykit.mating.problem import (
    Goal,
    MatingBody,
    MatingProblem,
    body_symmetry,
    mating_body,
    problem_diagonal,
)
from assemblykit.tolerance import MAX_MAGNITUDE, ModelTolerance, Tolerance, current


def _not_bool(value: Any) -> Any:
    """Refuse ``true``/``false`` where a number is expected (pydantic reads them as 1/0)."""
    if isinstance(value, bool):
        raise ValueError("expected a number, got a boolean")
    return value


Number = Annotated[
    float,
    BeforeValidator(_not_bool),
    Field(allow_inf_nan=False, ge=-MAX_MAGNITUDE, le=MAX_MAGNITUDE),
]
"""A finite coordinate or length of magnitude at most ``MAX_MAGNITUDE``."""

Length = Annotated[Number, Field(gt=0)]
Vector3 = tuple[Number, Number, Number]


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
    radius: Length
    height: Length


class PrimitiveModel(_Model):
    """One solid primitive: exactly one of ``box`` or ``cylinder``."""

    box: BoxModel | None = None
    cylinder: CylinderModel | None = None

    @model_validator(mode="after")
    def _one_kind(self) -> PrimitiveModel:
        if (self.box is None) == (self.cylinder is None):
            raise ValueError("give exactly one of box or cylinder")
        return self

    def primitive(self) -> Primitive:
        """The geometry value of this primitive."""
        if self.box is not None:
            return Box(self.box.min, self.box.max)
        assert self.cylinder is not None
        c = self.cylinder
        return Cylinder(c.point, c.axis, c.radius, c.height)


class ShapeModel(_Model):
    """A generated mesh: the union of ``add`` minus the union of ``cut``."""

    add: Annotated[list[PrimitiveModel], Field(min_length=1)]
    cut: list[PrimitiveModel] = Field(default_factory=list)


class RotationModel(_Model):
    """A symmetry element: the rotation by ``angle`` about the line (``point``, ``axis``)."""

    point: Vector3 = (0.0, 0.0, 0.0)
    axis: Vector3
    angle: Number | str


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


def load_problem(path: str | Path, tol: Tolerance | None = None) -> MatingProblem:
    """Read and validate a mating problem (docs/mating.md, "The problem file"): bodies with
    their features, compound features and meshes, and the goals (Liu & Popplestone 1990).

    Parameters
    ----------
    path : str or Path
        The problem file, ``.yaml``, ``.yml`` or ``.json``; mesh paths in it are read
        relative to its folder.
    tol : Tolerance, optional
        The tolerance policy, scaled to the bounding-box diagonal of the feature points and
        meshes (the current one when ``None``).

    Returns
    -------
    MatingProblem
        The validated problem, for :func:`assemblykit.mate`.

    Raises
    ------
    InputError
        The file is missing, unreadable or of another type, or its content does not
        validate (the field path is named).

    Examples
    --------
    >>> from pathlib import Path
    >>> import assemblykit
    >>> mating = Path(assemblykit.__file__).parent / "examples" / "mating"
    >>> assemblykit.load_problem(mating / "one_socket.yaml")
    MatingProblem(3 bodies, 2 goals, mm, one_socket.yaml)
    """
    path = Path(path)
    text = read_text(path, "problem")
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
    the bounding-box diagonal of the feature points and meshes (docs/architecture.md,
    "Tolerances")."""
    model = validated(
        ProblemModel,
        data,
        "a mating problem must hold a mapping with bodies and goals",
        source,
        lambda place: place,
    )
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
        tol = ModelTolerance.of((tol or current()).with_scale(problem_diagonal(features, meshes)))
        bodies = {
            name: _body(name, body, features[name], meshes[name], tol)
            for name, body in model.bodies.items()
        }
        goals = tuple(_goal(i, items, bodies) for i, items in enumerate(model.goals))
    except InputError as error:
        raise with_source(error, source) from None
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
    for cname, names in model.compound.items():
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
    symmetry = body_symmetry(features, mesh, _generators(model.symmetry, f"{place}.symmetry"), tol)
    return mating_body(name, features, model.compound, mesh, symmetry, model.sharable)


def _generators(
    spec: list[RotationModel] | Literal["none"] | None, where: str
) -> list[np.ndarray] | None:
    """The explicit symmetry generators: ``None`` to compute the group, ``[]`` for none."""
    if spec is None:
        return None
    if spec == "none":
        return []
    return [
        se3.rotation(r.axis, parse_angle(r.angle, f"{where}[{i}].angle"), r.point)
        for i, r in enumerate(spec)
    ]


def _mesh(spec: str | ShapeModel | None, folder: Path, where: str) -> trimesh.Trimesh | None:
    if spec is None:
        return None
    if isinstance(spec, str):
        try:
            return read_mesh(folder / spec)
        except GeometryError as error:
            raise GeometryError(error.detail, where=f"{where} ({spec})") from None
    try:
        return generated_mesh(
            [p.primitive() for p in spec.add], [p.primitive() for p in spec.cut], where
        )
    except SchemaError as error:
        raise SchemaError(error.detail, where=error.where or where) from None
