"""An assembly of rigid parts in assembled position (DESIGN.md §2, §5.2).

A :class:`Part` is a triangle mesh already placed in the world, the pose that placed it,
and, for CAD input, the exact surfaces of its faces. An :class:`Assembly` is an ordered
set of parts with their units and the file they came from; it computes (and caches) the
contacts between its parts (Liu 1997 and Wilson & Latombe 1992 start from "the
specification of the contact surfaces between parts") and the surface features
recognised on each part.

The geometry is computed by :mod:`assemblykit.geometry` (same layer); those modules are
imported inside the methods because they themselves take an :class:`Assembly`.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator, Mapping
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

import numpy as np
import trimesh
from numpy.typing import NDArray

from assemblykit.errors import UnknownNameError
from assemblykit.tolerance import Tolerance, current

if TYPE_CHECKING:
    from assemblykit.geometry.contacts import Contact
    from assemblykit.geometry.precision import Precision
    from assemblykit.geometry.recognition import Surface


@dataclass(frozen=True)
class Skipped:
    """An item of the input the loader could not use: ``item`` names it (e.g. a STEP
    entity ``#386 MANIFOLD_SOLID_BREP``) and ``reason`` says why. Answers about the
    assembly list these, so that a dropped part is never silent."""

    item: str
    reason: str

    def to_dict(self) -> dict[str, str]:
        """JSON form: ``item`` and ``reason``."""
        return {"item": self.item, "reason": self.reason}


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
    mm of DESIGN.md §4). ``exact`` is true when the geometry comes from exact CAD
    surfaces; otherwise the mesh thresholds of the tolerance policy apply. ``policy``
    is the tolerance policy given when loading (the current one when ``None``).
    ``precision`` is the input's own precision measured by the loader
    (:mod:`assemblykit.geometry.precision`); lengths are never compared more finely.
    ``skipped`` lists what the loader could not read (:class:`Skipped`) and ``warnings``
    what the reader reported while reading. ``groups`` names sets of parts the input
    keeps together (a STEP file's subassemblies), each listing its parts in order.
    """

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
    ) -> None:
        items = parts.values() if isinstance(parts, Mapping) else parts
        self.parts: dict[str, Part] = {p.name: p for p in items}
        self.groups: dict[str, tuple[str, ...]] = {
            group: kept
            for group, names in (groups or {}).items()
            if (kept := tuple(n for n in names if n in self.parts))
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
        self._contacts: dict[Tolerance, list[Contact]] = {}
        self._surfaces: dict[tuple[str, Tolerance], tuple[Surface, ...]] = {}

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
        """The model's size: the bounding-box diagonal (DESIGN.md §4), 1 when empty.

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

    def tolerance(self, tol: Tolerance | None = None) -> Tolerance:
        """The tolerance geometry is compared with: :meth:`policy_tolerance`, with its
        length raised to the measured :attr:`precision` of the input when that is coarser
        (``max(policy, measured)``, :mod:`assemblykit.geometry.precision`)."""
        policy = self.policy_tolerance(tol)
        if self.precision is None or self.precision.length <= policy.length:
            return policy
        return replace(policy, rel_length=self.precision.length / self.scale)

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

    def contacts(self, tol: Tolerance | None = None) -> list[Contact]:
        """The contacts between touching parts, computed once per tolerance
        (:func:`assemblykit.geometry.contacts.find_contacts`)."""
        from assemblykit.geometry.contacts import find_contacts

        key = self.tolerance(tol)
        if key not in self._contacts:
            self._contacts[key] = find_contacts(self, tol)
        return self._contacts[key]

    def surfaces(self, name: str, tol: Tolerance | None = None) -> tuple[Surface, ...]:
        """The surfaces of part ``name``: its exact CAD surfaces, else those recognised on
        its mesh (:func:`~assemblykit.geometry.recognition.recognise`)."""
        from assemblykit.geometry.recognition import recognise

        part = self.part(name)
        if part.surfaces:
            return part.surfaces
        key = (name, self.tolerance(tol))
        if key not in self._surfaces:
            self._surfaces[key] = recognise(part.mesh, key[1])
        return self._surfaces[key]

    def features(self, name: str, tol: Tolerance | None = None) -> list[Any]:
        """The surface features of part ``name`` as :mod:`assemblykit.features` objects."""
        return [s.feature() for s in self.surfaces(name, tol)]

    def _derived(self, parts: Iterable[Part], scale: float | None) -> Assembly:
        return Assembly(
            parts,
            units=self.units,
            units_source=self.units_source,
            source=self.source,
            exact=self.exact,
            scale=scale,
            policy=self.policy,
            precision=self.precision,
            skipped=self.skipped,
            warnings=self.warnings,
            groups=self.groups,
        )

    def subset(self, names: Iterable[str]) -> Assembly:
        """The sub-assembly of the named parts (in this assembly's order), with this
        assembly's scale; cached contacts among them are kept."""
        wanted = set(names)
        for name in wanted:
            self.part(name)
        sub = self._derived((p for n, p in self.parts.items() if n in wanted), self.scale)
        for key, found in self._contacts.items():
            sub._contacts[key] = [c for c in found if c.a in wanted and c.b in wanted]
        sub._surfaces = {k: v for k, v in self._surfaces.items() if k[0] in wanted}
        return sub

    def without_part(self, name: str) -> Assembly:
        """This assembly without part ``name`` (same scale, cached contacts kept)."""
        self.part(name)
        return self.subset(n for n in self.parts if n != name)

    def with_part(self, part: Part) -> Assembly:
        """This assembly with ``part`` added (or replaced). The scale is kept unless the
        new part lies outside the current bounds; cached contacts are kept when the
        scale is, and only the new part's contacts are then computed."""
        from assemblykit.geometry.contacts import find_contacts

        lo, hi = self.bounds
        inside = bool(np.all(part.mesh.bounds[0] >= lo) and np.all(part.mesh.bounds[1] <= hi))
        others = [p for n, p in self.parts.items() if n != part.name]
        grown = self._derived([*others, part], self.scale if inside and self.parts else None)
        grown._surfaces = {k: v for k, v in self._surfaces.items() if k[0] != part.name}
        if inside:
            for key, found in self._contacts.items():
                kept = [c for c in found if part.name not in (c.a, c.b)]
                grown._contacts[key] = kept + find_contacts(grown, key, only=part.name)
        return grown

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
        }
