"""An assembly of rigid parts in assembled position (docs/geometry.md, "Loaders and their
conventions").

A :class:`Part` is a triangle mesh already placed in the world, the pose that placed it,
and, for CAD input, the exact surfaces of its faces. An :class:`Assembly` is an ordered
set of parts with their units, the file they came from and the tolerance its geometry
is compared with. Both are plain data: what is derived from the parts is computed by the
layers above: the contacts between parts (Liu 1997 and Wilson & Latombe 1992 start from
"the specification of the contact surfaces between parts") and the surfaces recognised
on each part by :mod:`assemblykit.geometry`, the blocking terms, graphs and obstacles by
:mod:`assemblykit.blocking`.

Each assembly keeps what was derived from it in its :attr:`Assembly.memo`, a
:class:`Memo` created empty with it: one store per kind of derived data (a
:class:`Store`, its class defined by the layer that fills it), made on first use by
:meth:`Memo.of`. So derived data lives exactly as long as its assembly, two assemblies
never share a store, and nothing outside the assembly holds it. A sub-assembly starts
with :meth:`Memo.restricted`: what each store still holds for the parts it keeps
(contacts among them), the rest dropped. Every kind of assembly (:class:`AssemblyLike`:
meshes, voxels, polygons in the plane) carries a memo so.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator, Mapping, Set
from dataclasses import dataclass, field, replace
from typing import Any, ClassVar, Literal, Protocol, Self, TypeVar

import numpy as np
import trimesh
from numpy.typing import NDArray

from assemblykit.errors import UnknownNameError
from assemblykit.model.surfaces import Surface
from assemblykit.tolerance import ModelTolerance, Tolerance, current


@dataclass(frozen=True)
class Precision:
    """A measured precision of the input: ``length`` in model units, and ``source``,
    what it was measured from (shown by the ``contacts`` command); measured by
    :mod:`assemblykit.geometry.precision`."""

    length: float
    source: str


class Store(Protocol):
    """One kind of data derived from an assembly's parts, kept in its :class:`Memo`
    (:class:`assemblykit.geometry.contacts.GeometryMemo`: contacts and surfaces;
    :class:`assemblykit.geometry.interference.Solids`: the parts' manifold3d solids;
    :class:`assemblykit.blocking.cache.BlockingCache`: blocking terms, graphs and
    obstacles; :class:`assemblykit.geometry.polygons.PolygonContacts`: contact segments
    of polygons). Its class is created with no arguments, empty."""

    def restricted(self, names: Set[str]) -> Store | None:
        """What of it still holds for the parts ``names`` alone (the same part objects):
        a new store, or ``None`` when nothing of it does."""
        ...


StoreT = TypeVar("StoreT", bound=Store)


class Memo:
    """What was derived from one assembly's parts (module docstring): one :class:`Store`
    per kind, by its class."""

    __slots__ = ("_stores",)

    def __init__(self, stores: Iterable[Store] = ()) -> None:
        self._stores: dict[type[Store], Store] = {type(store): store for store in stores}

    def of(self, kind: type[StoreT]) -> StoreT:
        """The store of type ``kind``, created empty (``kind()``) the first time."""
        found = self._stores.get(kind)
        if found is None:
            found = self._stores[kind] = kind()
        assert isinstance(found, kind)
        return found

    def __contains__(self, kind: object) -> bool:
        """Whether a store of type ``kind`` was made."""
        return kind in self._stores

    def __len__(self) -> int:
        """How many stores were made."""
        return len(self._stores)

    def kinds(self) -> tuple[type[Store], ...]:
        """The types of the stores made, in the order they were made."""
        return tuple(self._stores)

    def restricted(self, names: Set[str]) -> Memo:
        """A new memo for the parts ``names`` alone: each store's
        :meth:`Store.restricted`, those with nothing left dropped."""
        return Memo(
            kept for store in self._stores.values() if (kept := store.restricted(names)) is not None
        )

    def __repr__(self) -> str:
        return f"Memo({', '.join(kind.__name__ for kind in self._stores)})"


class AssemblyLike(Protocol):
    """What every assembly offers, whatever its parts are (meshes, voxels, polygons in
    the plane): their names in order, the space they move in (``dimension``: 3, or 2
    for polygons), what the parts are (``kind``) and the tolerance policy scaled to the
    drawing. Code that works for every kind reads these, not the class: a layer whose
    answer differs by kind gives its variants side by side, as functions dispatched on
    the assembly (``functools.singledispatch``, the planar one registered by the module
    of the 2D case) or on ``dimension``, which tells :class:`Assembly` (3) from
    :class:`~assemblykit.model.polygons.PolygonAssembly` (2) to the type checker too.
    Each carries the :class:`Memo` of what was derived from it (``memo``)."""

    @property
    def memo(self) -> Memo:
        """What was derived from its parts, one store per kind."""
        ...

    @property
    def names(self) -> list[str]:
        """The part names, in order."""
        ...

    @property
    def dimension(self) -> int:
        """3 for parts in space, 2 for polygons in the plane."""
        ...

    @property
    def kind(self) -> str:
        """What the parts are: ``"meshes"``, ``"voxels"`` (the unit-cube meshes of a
        voxel puzzle's pieces, which also move on their lattice) or ``"polygons"``."""
        ...

    def tolerance(self, tol: Tolerance | None = None) -> ModelTolerance:
        """The tolerance the parts are compared with: the policy ``tol`` (the current
        one when ``None``) resolved for this drawing, or ``tol`` itself when it is this
        drawing's already (docs/architecture.md, "Tolerances")."""
        ...

    def sizes(self) -> dict[str, float]:
        """The size of each part: its volume (its area for a polygon in the plane)."""
        ...


@dataclass(frozen=True)
class Skipped:
    """An item of the input the loader could not use: ``item`` names it (e.g. a STEP
    entity ``#386 MANIFOLD_SOLID_BREP``) and ``reason`` says why; ``unreadable`` when the
    file itself is damaged there (a misspelled entity, a shell with no faces), where
    the command line refuses the file unless ``--partial`` (a solid read but not meshed
    is not). Answers about the assembly list these, so that a dropped part is never
    silent."""

    item: str
    reason: str
    unreadable: bool = False

    def to_dict(self) -> dict[str, str]:
        """JSON form: ``item`` and ``reason``."""
        return {"item": self.item, "reason": self.reason}


@dataclass(frozen=True)
class Overlap:
    """Two parts that share a volume beyond the interference threshold, ``volume`` in
    cubed model units, and what was done about it (``resolution``): ``"trimmed from
    NAME"`` (designed interference: the shared volume was cut from that part), ``"joined"``
    (the two move as one part) or ``""`` (left as it is: an obstacle in every direction).
    :func:`assemblykit.geometry.overlaps.resolve_overlaps` finds and resolves them."""

    a: str
    b: str
    volume: float
    resolution: str = ""
    units: str | None = field(default=None, compare=False)
    """The model's length unit, for showing ``volume`` with it (``mm³``); not in the JSON."""

    def to_dict(self) -> dict[str, str | float]:
        """JSON form: ``a``, ``b``, ``volume`` and ``resolution``."""
        return {"a": self.a, "b": self.b, "volume": self.volume, "resolution": self.resolution}


@dataclass(eq=False)
class Part:
    """One rigid part: ``mesh`` in world (assembled) position, ``pose`` the 4x4 transform
    that was applied to the source mesh to place it, ``surfaces`` the exact surfaces read
    from CAD (empty for meshes), ``source`` the file it came from, ``settled`` the
    translation the loader added to a rounded pose to close thin interpenetrations
    (:mod:`assemblykit.geometry.settling`; ``None`` when the pose is as read)."""

    name: str
    mesh: trimesh.Trimesh
    pose: NDArray[np.float64] = field(default_factory=lambda: np.eye(4))
    surfaces: tuple[Surface, ...] = ()
    source: str | None = None
    settled: tuple[float, float, float] | None = None

    @property
    def volume(self) -> float:
        """Enclosed volume of the mesh, in cubed model units."""
        return float(abs(self.mesh.volume))


class Assembly:
    """An ordered set of named parts in assembled position.

    ``units`` is the length unit of the coordinates and ``units_source`` how it was
    known (``declared`` in the file, read from the ``file`` format, or the ``default``
    mm of docs/geometry.md, "Loaders and their conventions"). ``exact`` is true when the
    geometry comes from exact CAD surfaces; otherwise the mesh thresholds of the tolerance
    policy apply. ``policy`` is the tolerance policy given when loading (the current one
    when ``None``).
    ``precision`` is the input's own precision measured by the loader
    (:mod:`assemblykit.geometry.precision`); lengths are never compared more finely.
    ``skipped`` lists what the loader could not read (:class:`Skipped`) and ``warnings``
    what the reader reported while reading. ``groups`` names sets of parts the input
    keeps together (a STEP file's subassemblies), each listing its parts in order;
    ``products`` the parts that are solids of one product of several solids (a STEP
    file's multi-body part: a locknut's nut and nylon insert), by the product's name.
    ``overlaps`` lists the interfering pairs found and what was done about each
    (:class:`Overlap`; empty until :func:`assemblykit.geometry.overlaps.resolve_overlaps`),
    and ``joined`` the parts that were made one, by the name of the part they became.
    ``supports`` are the parts the input stands on (docs/planning.md, "The ground"):
    those it declares (COMPAS ``is_support``) or, for a block assembly that declares
    none, those resting on its lowest plane; a plan keeps them and the ground plane under
    them, with +Z up.
    ``memo`` keeps what the layers above derived from the parts (:class:`Memo`, empty
    until they ask).
    """

    dimension: ClassVar[Literal[3]] = 3
    """The space the parts move in: 3 (a polygon assembly, drawn in the plane, has 2)."""

    kind: ClassVar[Literal["meshes", "voxels"]] = "meshes"
    """What the parts are: triangle meshes (``"voxels"`` for a voxel puzzle's pieces)."""

    def __init__(
        self,
        parts: Mapping[str, Part] | Iterable[Part],
        *,
        units: str = "mm",
        units_source: str = "default",
        source: str | None = None,
        exact: bool = False,
        scale: float | None = None,
        policy: Tolerance | None = None,
        precision: Precision | None = None,
        skipped: Iterable[Skipped] = (),
        warnings: Iterable[str] = (),
        groups: Mapping[str, Iterable[str]] | None = None,
        overlaps: Iterable[Overlap] = (),
        products: Mapping[str, Iterable[str]] | None = None,
        joined: Mapping[str, Iterable[str]] | None = None,
        supports: Iterable[str] = (),
    ) -> None:
        items = parts.values() if isinstance(parts, Mapping) else parts
        self.parts: dict[str, Part] = {p.name: p for p in items}
        wanted = set(supports)
        self.supports = tuple(name for name in self.parts if name in wanted)
        self.groups: dict[str, tuple[str, ...]] = {
            group: kept
            for group, names in (groups or {}).items()
            if (kept := tuple(n for n in names if n in self.parts))
        }
        self.products: dict[str, tuple[str, ...]] = {
            product: kept
            for product, names in (products or {}).items()
            if len(kept := tuple(n for n in names if n in self.parts)) > 1
        }
        self.units = units
        self.units_source = units_source
        self.source = source
        self.exact = exact
        self._scale = scale
        self.policy = policy
        self.precision = precision
        self.skipped = tuple(skipped)
        self.warnings = tuple(warnings)
        self.overlaps = tuple(overlaps)
        self.joined = {name: tuple(members) for name, members in (joined or {}).items()}
        self.memo = Memo()

    def __len__(self) -> int:
        return len(self.parts)

    def __iter__(self) -> Iterator[Part]:
        return iter(self.parts.values())

    def __getitem__(self, name: str) -> Part:
        return self.part(name)

    def __contains__(self, name: object) -> bool:
        return name in self.parts

    def __repr__(self) -> str:
        from assemblykit import formatting as fmt

        return fmt.summary(
            "Assembly", fmt.count(len(self), "part"), self.units, fmt.file_name(self.source)
        )

    def _repr_html_(self) -> str:
        """The parts as a table: triangles and volume (notebooks)."""
        from assemblykit import formatting as fmt

        units = self.units if self.units_source != "default" else None
        rows = [
            (name, str(len(p.mesh.faces)), fmt.number(p.volume, self.tolerance()))
            for name, p in self.parts.items()
        ]
        volume = fmt.header("volume", f"{units}³" if units else None)
        return fmt.html_summary(repr(self), ("part", "triangles", volume), rows)

    @property
    def names(self) -> list[str]:
        """Part names in order."""
        return list(self.parts)

    def sizes(self) -> dict[str, float]:
        """The volume of each part, by name in order."""
        return {name: part.volume for name, part in self.parts.items()}

    def part(self, name: str) -> Part:
        """The part called ``name``; :class:`UnknownNameError` if there is none."""
        try:
            return self.parts[name]
        except KeyError:
            raise UnknownNameError(
                f"no part named {name!r} (parts: {', '.join(self.parts)})", source=self.source
            ) from None

    @property
    def bounds(self) -> NDArray[np.float64]:
        """Axis-aligned bounds ``[[xmin, ymin, zmin], [xmax, ymax, zmax]]`` of all parts."""
        if not self.parts:
            return np.zeros((2, 3))
        boxes = np.array([p.mesh.bounds for p in self.parts.values()], dtype=np.float64)
        return np.array([boxes[:, 0].min(axis=0), boxes[:, 1].max(axis=0)])

    @property
    def scale(self) -> float:
        """The model's size: the bounding-box diagonal (docs/architecture.md, "Tolerances"),
        1 when empty.

        A sub-assembly made by :meth:`subset` keeps the scale of the assembly it came
        from, so that its parts are judged with the same tolerance."""
        if self._scale is None:
            lo, hi = self.bounds
            diagonal = float(np.linalg.norm(hi - lo))
            self._scale = diagonal if diagonal > 0 else 1.0
        return self._scale

    def policy_tolerance(self, tol: Tolerance | None = None) -> Tolerance:
        """The tolerance policy (``tol``, else the one the assembly was loaded with, else
        the current one) scaled to this model. For mesh input the mesh thresholds are a
        floor (tolerance.py): a looser length or angle asked for still applies."""
        policy = (tol or self.policy or current()).with_scale(self.scale)
        if self.exact:
            return policy
        return replace(
            policy,
            rel_length=max(policy.rel_length, policy.mesh_rel_length),
            angle=max(policy.angle, policy.mesh_angle),
        )

    def tolerance(self, tol: Tolerance | None = None) -> ModelTolerance:
        """The tolerance geometry is compared with: :meth:`policy_tolerance`, with its
        length raised to the measured :attr:`precision` of the input when that is coarser
        (``max(policy, measured)``, :mod:`assemblykit.geometry.precision`). A tolerance
        this model resolved already (of its scale) is returned as it is: resolving it
        again would give the same numbers."""
        if isinstance(tol, ModelTolerance) and tol.scale == self.scale:
            return tol
        policy = self.policy_tolerance(tol)
        if self.precision is None or self.precision.length <= policy.length:
            return ModelTolerance.of(policy)
        return ModelTolerance.of(replace(policy, rel_length=self.precision.length / self.scale))

    def tolerance_summary(self, tol: Tolerance | None = None) -> dict[str, Any]:
        """Which length tolerance applies and why: ``length`` (model units), ``relative``
        (to the scale), ``angle``, ``from`` (``policy`` or ``measured``), the policy's
        ``policy_length``, and the ``measured`` precision with what it was ``measured_from``."""
        policy, used = self.policy_tolerance(tol), self.tolerance(tol)
        return {
            "length": used.length,
            "relative": used.rel_length,
            "angle": used.angle,
            "from": "policy" if used == policy else "measured",
            "policy_length": policy.length,
            "measured": None if self.precision is None else self.precision.length,
            "measured_from": None if self.precision is None else self.precision.source,
        }

    @classmethod
    def like(
        cls, other: Assembly, parts: Iterable[Part] | None = None, scale: float | None = None
    ) -> Self:
        """An assembly of ``parts`` (default: those of ``other``) with everything else
        taken from ``other``: units, source, policy, precision, what was skipped, the
        warnings, groups, products, overlaps, joined parts and supports (those among
        ``parts``); ``scale`` as given (``None``: measured from the parts)."""
        return cls(
            other.parts.values() if parts is None else parts,
            units=other.units,
            units_source=other.units_source,
            source=other.source,
            exact=other.exact,
            scale=scale,
            policy=other.policy,
            precision=other.precision,
            skipped=other.skipped,
            warnings=other.warnings,
            groups=other.groups,
            overlaps=other.overlaps,
            products=other.products,
            joined=other.joined,
            supports=other.supports,
        )

    def _kept(self, parts: Iterable[Part], scale: float | None) -> Self:
        """This assembly with just ``parts``; its memo keeps what this one's holds for the
        parts they share (:meth:`Memo.restricted`)."""
        derived = type(self).like(self, parts, scale)
        derived.memo = self.memo.restricted(
            {n for n, p in derived.parts.items() if self.parts.get(n) is p}
        )
        return derived

    def subset(self, names: Iterable[str]) -> Self:
        """The sub-assembly of the named parts (in this assembly's order), with this
        assembly's scale; contacts already computed among them are kept."""
        wanted = set(names)
        for name in wanted:
            self.part(name)
        return self._kept((p for n, p in self.parts.items() if n in wanted), self.scale)

    def without_part(self, name: str) -> Self:
        """This assembly without part ``name`` (same scale, computed contacts kept)."""
        self.part(name)
        return self.subset(n for n in self.parts if n != name)

    def with_part(self, part: Part) -> Self:
        """This assembly with ``part`` added (or replaced). The scale is kept unless the
        new part lies outside the current bounds; contacts already computed among the
        other parts are kept, so that only the new part's are then computed."""
        lo, hi = self.bounds
        inside = bool(np.all(part.mesh.bounds[0] >= lo) and np.all(part.mesh.bounds[1] <= hi))
        others = [p for n, p in self.parts.items() if n != part.name]
        return self._kept([*others, part], self.scale if inside and self.parts else None)

    def to_dict(self) -> dict[str, Any]:
        """Summary: source, units, scale and per-part triangle count, volume, bounds,
        source file and the ``settled`` translation of its pose (``None`` if as read);
        the items the loader ``skipped`` and its ``warnings``."""
        return {
            "source": self.source,
            "units": self.units,
            "units_source": self.units_source,
            "scale": self.scale,
            "parts": {
                name: {
                    "triangles": len(p.mesh.faces),
                    "volume": p.volume,
                    "bounds": p.mesh.bounds.tolist(),
                    "source": p.source,
                    "settled": None if p.settled is None else list(p.settled),
                }
                for name, p in self.parts.items()
            },
            "skipped": [item.to_dict() for item in self.skipped],
            "warnings": list(self.warnings),
            "supports": list(self.supports),
        }


def lowest_parts(
    assembly: Assembly, direction: NDArray[np.float64] | Iterable[float], tol: Tolerance
) -> tuple[str, ...]:
    """The parts touching the lowest plane across ``direction`` (gravity, or down): those
    whose lowest point along it is the assembly's lowest, within the length tolerance."""
    down = np.asarray(direction, dtype=np.float64)
    depth = np.array([float((p.mesh.vertices @ down).max()) for p in assembly.parts.values()])
    return tuple(
        name for name, d in zip(assembly.names, depth, strict=True) if d >= depth.max() - tol.length
    )
