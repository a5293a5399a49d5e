"""Fasteners in plans: a part that leaves along the axis of its cylindrical fits.

A fitter reads a disassembly step that draws one part out of round holes along their
common axis as a fastener coming out: a pin pulled, or a screw turned out where a thread
is modelled or implied. Here a step names its part a fastener when the part is the
inner (shaft) side of a cylindrical contact with a part it leaves
(:class:`~assemblykit.geometry.contacts.CurvedPatch`) whose axis is the step's direction
within the angle tolerance, and a **screw** when it also interferes with one of those
parts by design (a thread cut into its pilot hole or a nut's insert, resolved by
:func:`~assemblykit.geometry.overlaps.resolve_overlaps`); otherwise a **pin**. A screw
comes out by the helical motion of the screw group about that axis (Liu 1997:
the helical pair); its pitch is not read from the model. Bolts and screws drawn at
their nominal diameter, with no thread modelled and no interference, are reported as
pins (docs/planning.md, "Fasteners").
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from assemblykit.geometry.contacts import assembly_contacts
from assemblykit.model.assembly import Assembly
from assemblykit.tolerance import Tolerance

FastenerKind = Literal["screw", "pin"]


@dataclass(frozen=True, eq=False)
class Fastener:
    """The part of a step read as a fastener (module docstring): its ``kind``, the unit
    ``axis`` it leaves along (the step's direction) and the parts whose holes it leaves
    (``holes``, in the assembly's order)."""

    part: str
    kind: FastenerKind
    axis: NDArray[np.float64]
    holes: tuple[str, ...]

    def to_dict(self) -> dict[str, Any]:
        """JSON form: ``part``, ``kind`` (``"screw"`` or ``"pin"``), ``axis``, ``holes``."""
        return {
            "part": self.part,
            "kind": self.kind,
            "axis": [float(x) + 0.0 for x in self.axis],
            "holes": list(self.holes),
        }


def step_fastener(
    assembly: Assembly,
    parts: Sequence[str],
    direction: NDArray[np.float64],
    rest: Sequence[str],
    tol: Tolerance,
) -> Fastener | None:
    """The fastener a step moving ``parts`` along ``direction`` out of ``rest`` takes
    out, or ``None`` (module docstring): a single part with a cylindrical fit along the
    direction in some part of ``rest``."""
    if len(parts) != 1:
        return None
    (part,) = parts
    staying = set(rest)
    d = np.asarray(direction, dtype=np.float64) / np.linalg.norm(direction)
    holes = []
    for contact in assembly_contacts(assembly, tol):
        other = contact.b if contact.a == part else contact.a if contact.b == part else None
        if other is None or other not in staying:
            continue
        if any(
            patch.kind == "cylindrical"
            and patch.inner == part
            and patch.axis is not None
            and abs(float(patch.axis @ d)) >= np.cos(tol.mesh_angle)
            for patch in contact.curved
        ):
            holes.append(other)
    if not holes:
        return None
    order = {name: k for k, name in enumerate(assembly.names)}
    holes.sort(key=order.__getitem__)
    threaded = any({o.a, o.b} & {part} and {o.a, o.b} & set(holes) for o in assembly.overlaps)
    return Fastener(part, "screw" if threaded else "pin", d, tuple(holes))
