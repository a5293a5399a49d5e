"""Fasteners in plans: a part that leaves along the axis of its cylindrical fits.

A fitter reads a disassembly step that draws one part out of round holes along their
common axis as a fastener coming out: a pin pulled, or a screw turned out where a thread
is modelled or implied. Here a step names its part a fastener when the part is the
inner (shaft) side of a cylindrical contact with a part it leaves
(:class:`~assemblykit.geometry.contacts.CurvedPatch`) whose axis is the step's direction
within the angle tolerance and whose every point lies within :data:`HEAD_RATIO` radii
of that fit from the axis (a shank and a head: a servo whose output spline is pressed
into a horn leaves along the spline's axis too, and is no fastener), and a **screw**
when it also interferes with one of those
parts by design deeper than :data:`PRESS_FIT_SHARE` of the fit's radius (a thread cut
into its pilot hole or a nut's insert, resolved by
:func:`~assemblykit.geometry.overlaps.resolve_overlaps`); **pressed** when it interferes
less deeply (a press fit); otherwise a **pin**, unless its name writes the ISO size
it is drawn at (``M3 Bolt`` at 3 mm: :func:`named_size`), which makes it a screw
threaded into the last of its holes on its way in. Other bolts and screws drawn at their
nominal diameter, with no thread modelled and no interference, are reported as pins
(docs/planning.md, "Fasteners").

A **nut** is the outer side of such a fit round a bolt-like shaft (a part within
:data:`HEAD_RATIO` radii of the axis): a part itself within those radii, between
:data:`NUT_LENGTH` and :data:`NUT_LONGEST` diameters long along the axis (a washer is
thinner, a spacer longer), whose outline is a polygon, not round (:data:`NUT_FLATS`: a
hexagon or a square; a spacer is round). A nut implies a thread: a nut leaving along the
axis off the bolt's end that stays is unscrewed, the turns being the distance from its
back face to the bolt's tip over the pitch; a shaft leaving a nut that stays is a screw
turned out of it (held by the nut, as a fitter turns a bolt out). A shaft that a nut
came off earlier in the plan is a **bolt** when it then leaves along the same axis:
pulled out of its holes, of the nut's thread.

A screw comes out by the helical motion of the screw group about its axis (Liu 1997:
the helical pair; :meth:`Fastener.motion`), whose sweep is the translation's for a part
round about its axis, so the step's path is checked as a translation. Its **thread** is
the size written in its name (``M3x20``), else implied by the diameter it was drawn at
(the outer diameter of the ring it shares with its hole), when that is within
:data:`NOMINAL_MATCH` of an ISO metric size, where the model's unit is
one of :data:`MILLIMETRES` (millimetres unless the input says otherwise): the coarse
pitch of ISO 261 for that size
(:data:`ISO_COARSE_PITCH`; a right-hand thread, unscrewed by turning anticlockwise seen
from its head), and the **turns** it takes are the distance its tip travels until it
leaves the last hole it is threaded into, over the pitch.
"""

from __future__ import annotations

import math
import re
from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from assemblykit.algebra import SymmetryGroup, se3
from assemblykit.geometry.contact_values import CurvedPatch
from assemblykit.geometry.contacts import assembly_contacts
from assemblykit.geometry.overlaps import ring_radius
from assemblykit.model.assembly import Assembly
from assemblykit.tolerance import ModelTolerance

FastenerKind = Literal["screw", "pin", "pressed", "nut", "bolt"]

ISO_COARSE_PITCH: dict[float, float] = {
    1.0: 0.25,
    1.2: 0.25,
    1.4: 0.3,
    1.6: 0.35,
    2.0: 0.4,
    2.5: 0.45,
    3.0: 0.5,
    3.5: 0.6,
    4.0: 0.7,
    5.0: 0.8,
    6.0: 1.0,
    8.0: 1.25,
    10.0: 1.5,
    12.0: 1.75,
    14.0: 2.0,
    16.0: 2.0,
    20.0: 2.5,
    24.0: 3.0,
    30.0: 3.5,
    36.0: 4.0,
}
"""The coarse pitch (mm) of each ISO metric thread size (nominal diameter, mm), ISO 261."""

NOMINAL_MATCH = 0.1
"""How far (a fraction of the size) a fit's diameter may be from an ISO size to take it
for that size: a self-tapping M3 screw cut to a 2.9 mm pilot hole is an M3."""

HEAD_RATIO = 3.0
"""How far from its axis, in radii of its fit, a fastener reaches: the heads of ISO
screws and bolts (hexagon across corners, pan, cheese, socket, countersunk and flange
heads) are at most about 2.4 shank diameters wide, under 2.5 radii of the fit."""

PRESS_FIT_SHARE = 0.01
"""The deepest interference, as a share of a fit's radius, of a part **pressed** into
its hole (a bearing, a bushing, a dowel): ISO interference fits press by a few
thousandths of the diameter, while a thread cut into its pilot hole goes deeper (a
self-tapping M3 in a 2.9 mm hole, 3% of the radius). The depth is read as the shared
volume over the fit's surface (its circumference times its length)."""

NUT_LENGTH = 0.35
"""The shortest nut along its axis, in diameters of its thread: ISO hexagon nuts are
0.8 to 0.9 diameters long, thin nuts 0.5; a plain washer is 0.2 thick."""

NUT_LONGEST = 1.5
"""The longest nut along its axis, in diameters of its thread (a high nut is about
1.2); a spacer round a pin is longer."""

NUT_FLATS = 1.1
"""How far from round a nut's outline is at least (its widest reach from the axis over
its narrowest): a hexagon's is 1.155, a square's 1.414; a round spacer, washer or
bushing is 1."""

OUTLINE_VIEWS = 72
"""The directions across the axis a nut's outline is measured from (every 5 degrees)."""

PILOT_HOLE = 0.7
"""The smallest fit, a fraction of the size written in a screw's name, that the name is
believed for: self-tapping screws are cut into pilot holes of about 0.8 of their size
(an M2 into 1.6 mm, an M3 into 2.5 mm)."""

MILLIMETRES = {"mm": 1.0, "cm": 10.0, "m": 1000.0, "in": 25.4}
"""Millimetres per model unit, for the units whose threads are sized."""


@dataclass(frozen=True)
class Thread:
    """A screw's thread, implied by its diameter (module docstring): the ISO ``size``
    (``"M3"``), the ``pitch`` (model units per turn, a right-hand thread) and the
    ``turns`` it takes to come out."""

    size: str
    pitch: float
    turns: float

    def to_dict(self) -> dict[str, Any]:
        """JSON form: ``size``, ``pitch`` (model units), ``turns``, ``implied`` (true: read
        from the diameter, not from a modelled thread)."""
        return {"size": self.size, "pitch": self.pitch, "turns": self.turns, "implied": True}


def named_size(name: str) -> float | None:
    """The ISO metric size written in a part's name, as a fitter reads it (``"M2x10"``,
    ``"BS EN ISO 7045 - M2 x 4"``, ``"M3 screw"``: 2, 2, 3), or ``None``.

    >>> named_size("M2x10_1"), named_size("Laserteil 3"), named_size("M1.6 x 5")
    (2.0, None, 1.6)
    """
    for found in _SIZE_IN_NAME.finditer(name):
        size = float(found.group(1))
        if size in ISO_COARSE_PITCH:
            return size
    return None


_SIZE_IN_NAME = re.compile(r"(?<![A-Za-z0-9])M(\d+(?:\.\d+)?)(?![0-9.])")


def implied_thread(
    diameter: float, travel: float, units: str | None, name: str = ""
) -> Thread | None:
    """The ISO thread of a screw whose fit has ``diameter`` and whose tip travels
    ``travel`` while threaded (model units of ``units``), or ``None`` when the unit is
    not known or no size is: the size written in its ``name`` (:func:`named_size`: a
    self-tapping M2 cut to a 1.6 mm pilot hole is an M2, not an M1.6) where the
    diameter is between :data:`PILOT_HOLE` of it and :data:`NOMINAL_MATCH` above it,
    else the ISO size within :data:`NOMINAL_MATCH` of the diameter (module docstring).

    >>> implied_thread(2.9, 6.0, "mm")
    Thread(size='M3', pitch=0.5, turns=12.0)
    >>> implied_thread(1.6, 4.0, "mm", "M2x10_1")
    Thread(size='M2', pitch=0.4, turns=10.0)
    """
    scale = MILLIMETRES.get(units or "")
    if scale is None or not diameter > 0:
        return None
    millimetres = diameter * scale
    size = named_size(name)
    if size is None or not PILOT_HOLE * size <= millimetres <= (1 + NOMINAL_MATCH) * size:
        size = min(ISO_COARSE_PITCH, key=lambda nominal: abs(nominal - millimetres))
        if abs(size - millimetres) > NOMINAL_MATCH * size:
            return None
    pitch = ISO_COARSE_PITCH[size] / scale
    name = f"M{size:g}"
    return Thread(name, pitch, round(max(travel, 0.0) / pitch, 1))


@dataclass(frozen=True, eq=False)
class Fastener:
    """The part of a step read as a fastener (module docstring): its ``kind``, the unit
    ``axis`` it leaves along (the step's direction) and the parts whose holes it leaves
    (``holes``, in the assembly's order)."""

    part: str
    kind: FastenerKind
    axis: NDArray[np.float64]
    holes: tuple[str, ...]
    center: NDArray[np.float64] | None = None
    """A point of the axis (the fit's)."""
    diameter: float | None = None
    """The diameter of its fit (model units)."""
    thread: Thread | None = None
    """A screw's thread, where implied (module docstring)."""
    named: bool = False
    """Whether it is a screw by its name alone (drawn at the size its name writes,
    sharing no volume with its holes)."""

    def motion(self) -> SymmetryGroup:
        """The motion that takes it out: the helical group about its axis, of the
        thread's pitch (``pitch / 2 pi`` per radian, right-handed), for a screw or nut
        whose thread is known; the translations along the axis otherwise (a bolt whose
        nut is off is pulled)."""
        center = np.zeros(3) if self.center is None else self.center
        if self.thread is None or self.kind == "bolt":
            return SymmetryGroup.prismatic(self.axis)
        return SymmetryGroup.helical(center, self.axis, self.thread.pitch / (2 * math.pi))

    def summary(self) -> str:
        """In words: ``"unscrew M3 (pitch 0.5, 12 turns)"``, ``"unscrew"``, ``"unscrew nut
        M5 (pitch 0.8, 6.2 turns)"``, ``"pull bolt M5"``, ``"pull pin"`` or ``"press
        out"``."""
        if self.kind == "pin":
            return "pull pin"
        if self.kind == "pressed":
            return "press out"
        thread = self.thread
        if self.kind == "bolt":
            return "pull bolt" + (f" {thread.size}" if thread else "")
        said = "unscrew nut" if self.kind == "nut" else "unscrew"
        if thread is None:
            return said
        return f"{said} {thread.size} (pitch {thread.pitch:g}, {thread.turns:g} turns)"

    def to_dict(self) -> dict[str, Any]:
        """JSON form: ``part``, ``kind`` (``"screw"``, ``"pin"``, ``"pressed"``,
        ``"nut"`` or ``"bolt"``), ``axis``, ``holes`` (for a nut, its bolt), ``diameter``
        (of the fit), and where a thread is implied ``thread`` (:meth:`Thread.to_dict`)."""
        return {
            "part": self.part,
            "kind": self.kind,
            "axis": [float(x) + 0.0 for x in self.axis],
            "holes": list(self.holes),
            **({} if self.diameter is None else {"diameter": self.diameter}),
            **({} if self.thread is None else {"thread": self.thread.to_dict()}),
        }


def drawn_summary(fasteners: Sequence[Fastener]) -> str:
    """In words, the screws, nuts, bolts, pins and pressed parts of one step:
    ``"unscrew 5 x M3, 1 x M2; unscrew nuts 2 x M5; pull bolts 2 x M5; pull 1 pin;
    press out 1"`` (counted by their implied size, ``"unscrew 2"`` where none is
    implied); empty for none."""
    verbs: tuple[tuple[FastenerKind, str], ...] = (
        ("screw", "unscrew"),
        ("nut", "unscrew nuts"),
        ("bolt", "pull bolts"),
    )
    said = [
        f"{verb} {_counted(fasteners, kind)}"
        for kind, verb in verbs
        if any(f.kind == kind for f in fasteners)
    ]
    pins = sum(f.kind == "pin" for f in fasteners)
    pressed = sum(f.kind == "pressed" for f in fasteners)
    said += [f"pull {pins} pin{'s' * (pins > 1)}"] if pins else []
    return "; ".join([*said, *([f"press out {pressed}"] if pressed else [])])


def _counted(fasteners: Sequence[Fastener], kind: FastenerKind) -> str:
    """The fasteners of ``kind`` counted by their implied size: ``"5 x M3, 1 x M2"``,
    ``"2"`` where none is implied."""
    sizes = Counter(f.thread.size if f.thread else "" for f in fasteners if f.kind == kind)
    return ", ".join(f"{n} x {size}" if size else str(n) for size, n in sizes.items())


def step_fastener(
    assembly: Assembly,
    parts: Sequence[str],
    direction: NDArray[np.float64],
    rest: Sequence[str],
    tol: ModelTolerance,
) -> Fastener | None:
    """The fastener a step moving ``parts`` along ``direction`` out of ``rest`` takes
    out, or ``None`` (module docstring): a single part with a cylindrical fit along the
    direction in some part of ``rest``, as its shaft (a screw, pin or pressed part) or
    as a nut."""
    if len(parts) != 1:
        return None
    (part,) = parts
    d = np.asarray(direction, dtype=np.float64) / np.linalg.norm(direction)
    fits = _fits(assembly, part, d, set(rest), tol, inner=True)
    if not fits:
        return _nut(assembly, part, d, _fits(assembly, part, d, set(rest), tol, inner=False))
    order = {name: k for k, name in enumerate(assembly.names)}
    holes = sorted(fits, key=order.__getitem__)
    shared = {
        hole: sum(o.volume for o in assembly.overlaps if {o.a, o.b} == {part, hole})
        for hole in holes
    }
    pressed = [hole for hole in holes if shared[hole] > 0]
    threaded = [
        hole
        for hole in holes
        if (hole in pressed and _cut_deeper_than_a_press(shared[hole], fits[hole]))
        or _nut_on_bolt(assembly, hole, part, fits[hole], d)
    ]
    first = fits[holes[0]][0]
    diameter = 2 * max(patch.radius for hole in holes for patch in fits[hole])
    center = np.asarray(first.center, dtype=np.float64)
    if _reach(assembly[part].mesh.vertices, center, d) > HEAD_RATIO * diameter / 2:
        return None
    named = not threaded and not pressed and _named_for(part, diameter, assembly.units)
    if named:
        threaded = [min(holes, key=lambda hole: min(_near_end(p, d) for p in fits[hole]))]
    thread = None
    if threaded:
        tip = float((assembly[part].mesh.vertices @ d).min())
        travel = max(_far_end(patch, d) for hole in threaded for patch in fits[hole]) - tip
        drawn = max(_drawn_diameter(shared[hole], fits[hole]) for hole in threaded)
        thread = implied_thread(drawn, travel, assembly.units, part)
    return Fastener(
        part,
        "screw" if threaded else "pressed" if pressed else "pin",
        d,
        tuple(holes),
        center,
        diameter,
        thread,
        named,
    )


def _named_for(part: str, diameter: float, units: str | None) -> bool:
    """Whether the name of ``part`` writes an ISO size (:func:`named_size`) that its fit
    of ``diameter`` (model units of ``units``) is drawn at: between :data:`PILOT_HOLE`
    of the size and :data:`NOMINAL_MATCH` above it."""
    size, scale = named_size(part), MILLIMETRES.get(units or "")
    if size is None or scale is None:
        return False
    return PILOT_HOLE * size <= diameter * scale <= (1 + NOMINAL_MATCH) * size


def _fits(
    assembly: Assembly,
    part: str,
    direction: NDArray[np.float64],
    staying: set[str],
    tol: ModelTolerance,
    *,
    inner: bool,
) -> dict[str, list[CurvedPatch]]:
    """The cylindrical fits of ``part`` along the unit ``direction`` with each part of
    ``staying`` it touches, as their shaft (``inner``) or their hole."""
    fits: dict[str, list[CurvedPatch]] = {}
    for contact in assembly_contacts(assembly, tol):
        other = contact.b if contact.a == part else contact.a if contact.b == part else None
        if other is None or other not in staying:
            continue
        found = [
            patch
            for patch in contact.curved
            if patch.kind == "cylindrical"
            and (patch.inner == part) is inner
            and patch.axis is not None
            and abs(float(patch.axis @ direction)) >= np.cos(tol.mesh_angle)
        ]
        if found:
            fits.setdefault(other, []).extend(found)
    return fits


def _nut(
    assembly: Assembly,
    part: str,
    direction: NDArray[np.float64],
    fits: dict[str, list[CurvedPatch]],
) -> Fastener | None:
    """``part`` as a nut leaving the bolt its hole ``fits`` along ``direction`` (module
    docstring), or ``None``: one shaft, both within :data:`HEAD_RATIO` radii of the
    axis, the part at least :data:`NUT_LENGTH` diameters long."""
    if len(fits) != 1:
        return None
    ((bolt, patches),) = fits.items()
    if not _nut_on_bolt(assembly, part, bolt, patches, direction):
        return None
    radius = max(patch.radius for patch in patches)
    shared = sum(o.volume for o in assembly.overlaps if {o.a, o.b} == {part, bolt})
    tip = float((assembly[bolt].mesh.vertices @ direction).max())
    travel = tip - float((assembly[part].mesh.vertices @ direction).min())
    thread = implied_thread(_drawn_diameter(shared, patches), travel, assembly.units, part)
    center = np.asarray(patches[0].center, dtype=np.float64)
    return Fastener(part, "nut", direction, (bolt,), center, 2 * radius, thread)


def _nut_on_bolt(
    assembly: Assembly,
    nut: str,
    bolt: str,
    patches: Sequence[CurvedPatch],
    axis: NDArray[np.float64],
) -> bool:
    """Whether ``nut`` fits round ``bolt`` by ``patches`` along the unit ``axis`` as a
    nut does (module docstring): both within :data:`HEAD_RATIO` radii of the axis, the
    nut between :data:`NUT_LENGTH` and :data:`NUT_LONGEST` diameters long, its outline
    a polygon (:data:`NUT_FLATS`)."""
    center = np.asarray(patches[0].center, dtype=np.float64)
    radius = max(patch.radius for patch in patches)
    around, shaft = assembly[nut].mesh.vertices, assembly[bolt].mesh.vertices
    reach = HEAD_RATIO * radius
    if _reach(around, center, axis) > reach or _reach(shaft, center, axis) > reach:
        return False
    along = around @ axis
    length = float(along.max() - along.min())
    if not NUT_LENGTH * 2 * radius <= length <= NUT_LONGEST * 2 * radius:
        return False
    return _flats(around - center, axis) >= NUT_FLATS


def _flats(points: NDArray[np.float64], axis: NDArray[np.float64]) -> float:
    """How far ``points`` (about a point of the unit ``axis``) are from round about it:
    their widest reach over their narrowest, seen from :data:`OUTLINE_VIEWS` directions
    across the axis (a hexagon's corners over its flats, 2 / sqrt 3; a faceted
    cylinder's, 1 to within its facets)."""
    u, v = se3.axis_basis(axis)
    angles = np.linspace(0.0, 2 * np.pi, OUTLINE_VIEWS, endpoint=False)
    views = np.outer(np.cos(angles), u) + np.outer(np.sin(angles), v)
    reach = (points @ views.T).max(axis=0)
    return float(reach.max() / reach.min()) if reach.min() > 0 else 0.0


def bolts_after_nuts(fasteners: Sequence[Sequence[Fastener]]) -> list[tuple[Fastener, ...]]:
    """The fasteners of a plan's steps (``fasteners[k]``: step ``k``'s, in order) with
    each pin that a nut came off in an earlier step, leaving along the nut's axis, read
    as a **bolt** (module docstring) of the nut's thread, with no turns left."""
    nuts: dict[str, Fastener] = {}
    read: list[tuple[Fastener, ...]] = []
    for step in fasteners:
        read.append(tuple(_as_bolt(f, nuts.get(f.part)) for f in step))
        nuts.update((f.holes[0], f) for f in step if f.kind == "nut")
    return read


def _as_bolt(fastener: Fastener, nut: Fastener | None) -> Fastener:
    """``fastener`` as a bolt where it is a pin, or a screw by its name alone, leaving
    along the axis of the ``nut`` that came off it."""
    unthreaded = fastener.kind == "pin" or fastener.named
    if nut is None or not unthreaded or abs(float(fastener.axis @ nut.axis)) < 0.5:
        return fastener
    thread = None if nut.thread is None else replace(nut.thread, turns=0.0)
    return replace(fastener, kind="bolt", thread=thread, named=False)


def _fit_length(patches: Sequence[CurvedPatch]) -> float | None:
    """The stretch of the axis the fits ``patches`` cover together (one fit may come as
    several patches), ``None`` when one has no known extent."""
    axis = patches[0].axis
    if axis is None or any(patch.extent is None for patch in patches):
        return None
    ends = [
        float(np.asarray(patch.center) @ axis) + along
        for patch in patches
        if patch.extent is not None
        for along in patch.extent
    ]
    return max(ends) - min(ends)


def _cut_deeper_than_a_press(volume: float, patches: Sequence[CurvedPatch]) -> bool:
    """Whether a part sharing ``volume`` with a hole through the fits ``patches`` cuts
    into it deeper than :data:`PRESS_FIT_SHARE` of their radius: a thread, not a press
    fit (a fit of unknown length counts as a thread)."""
    radius = max(patch.radius for patch in patches)
    length = _fit_length(patches)
    if length is None:
        return True
    return volume > PRESS_FIT_SHARE * radius * 2 * math.pi * radius * length


def _drawn_diameter(volume: float, patches: Sequence[CurvedPatch]) -> float:
    """The diameter a screw was drawn at, from the ring ``volume`` it shares with a
    hole through the fits ``patches`` (the ring's outer diameter, the hole's inside
    it, along the fits' length): a screw drawn at its nominal size (M4, 4 mm) in a
    hole of its tap drill (3.3 mm) is an M4, not the M3.5 the hole's diameter is near;
    the fit's diameter where the length is not known."""
    radius = max(patch.radius for patch in patches)
    length = _fit_length(patches)
    if not length:
        return 2 * radius
    return 2 * ring_radius(volume, radius, length)


def _reach(
    points: NDArray[np.float64], center: NDArray[np.float64], axis: NDArray[np.float64]
) -> float:
    """The largest distance of ``points`` from the line through ``center`` along the
    unit ``axis``."""
    offsets = np.asarray(points, dtype=np.float64) - center
    return float(np.linalg.norm(offsets - np.outer(offsets @ axis, axis), axis=1).max(initial=0.0))


def _near_end(patch: CurvedPatch, direction: NDArray[np.float64]) -> float:
    """How far along ``direction`` the fit ``patch`` begins: how far against it it
    reaches, negated (:func:`_far_end` along the opposite direction)."""
    return -_far_end(patch, -direction)


def _far_end(patch: CurvedPatch, direction: NDArray[np.float64]) -> float:
    """How far along ``direction`` the fit ``patch`` reaches (its whole surface when its
    extent is not known)."""
    assert patch.axis is not None
    along = float(patch.axis @ direction)
    base = float(np.asarray(patch.center) @ direction)
    if patch.extent is not None:
        return base + max(along * patch.extent[0], along * patch.extent[1])
    points = patch.points if patch.points is not None else np.asarray([patch.center])
    return float((np.asarray(points) @ direction).max())
