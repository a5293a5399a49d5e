"""The answer of RAPT inference: a pose set per body instance (docs/architecture.md, "Conventions";
docs/tutorial.md, "JSON").

A result that is a set is reported as a set: every body instance ``"<body>@<situation>"``
has a representative pose, its remaining dof and motion group with invariants in world
coordinates, and the number of solutions (with the other poses when there are finitely
many). Inconsistencies are answers, listed as conflicts naming the relations and the
size of the mismatch; a mismatch within ``NEARLY_CONSISTENT`` times the tolerance is
*nearly consistent* and carries the tolerance that accepts it (``needed_tolerance``).
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from enum import StrEnum
from typing import Any

import numpy as np

from assemblykit.algebra import Kind
from assemblykit.tolerance import ORDER_RESOLUTION, Tolerance


class Status(StrEnum):
    """The answer for the whole task (docs/tutorial.md, "JSON"; :func:`status_of`)."""

    SOLVED = "solved"
    AMBIGUOUS = "ambiguous"
    UNDERCONSTRAINED = "underconstrained"
    INCONSISTENT = "inconsistent"


STATUSES: tuple[Status, ...] = tuple(Status)


class Mechanism(StrEnum):
    """The freedoms of higher pairs that are no Hervé family (the ``mechanism`` of a
    :class:`BodyInstanceResult`, said in words by :data:`MECHANISMS`)."""

    POINT_IN_PLANE = "point-in-plane"
    POINT_ON_LINE = "point-on-line"
    PLANAR_POINT_ON_LINE = "planar-point-on-line"
    LINE_ON_PLANE = "line-on-plane"
    ROLL_AND_SLIDE = "roll-and-slide"


MECHANISM = "mechanism"
"""The motion of an instance whose freedom is no Hervé family (a higher pair, a closed
loop, a coupled relation, a residue solved numerically)."""

MOTIONS: tuple[str, ...] = (*Kind, MECHANISM)
"""Every motion of a body instance: Hervé's families (:class:`~assemblykit.algebra.Kind`)
and :data:`MECHANISM`."""

INVARIANT_KEYS = ("point", "direction", "normal", "center", "pitch")

UNSIGNED_KEYS = ("direction", "normal")
"""The invariants whose sign says nothing: a slide along ``u`` is the slide along
``-u``, a turn or screw about ``u`` the one about ``-u`` (same pitch), a plane's motions
those of its flipped normal (:func:`unsigned_axes`)."""


def unsigned_axes(invariants: Mapping[str, Any]) -> dict[str, Any]:
    """``invariants`` with each unsigned direction (:data:`UNSIGNED_KEYS`) turned so that
    its first component larger than :data:`~assemblykit.tolerance.ORDER_RESOLUTION` of
    its length is positive: the deterministic sign of docs/architecture.md,
    "Tolerances" (``(0, -1, 0)`` and ``(1e-32, 1, 0)`` both become ``(0, 1, 0)``'s sign)."""
    out = dict(invariants)
    for key in UNSIGNED_KEYS:
        if key not in out:
            continue
        vector = np.asarray(out[key], dtype=np.float64)
        large = np.flatnonzero(np.abs(vector) > ORDER_RESOLUTION * np.linalg.norm(vector))
        if len(large) and vector[large[0]] < 0:
            out[key] = -vector + 0.0
    return out


def _plain(value: Any) -> Any:
    """JSON-ready copy: arrays become lists of floats."""
    if isinstance(value, np.ndarray):
        return value.astype(float).tolist()
    if isinstance(value, np.floating | np.integer):
        return value.item()
    return value


@dataclass(frozen=True)
class BodyInstanceResult:
    """The pose set of one body in one situation.

    ``solutions`` is the number of poses (``None`` for an infinite discrete family, a
    lattice); for a continuum (``dof > 0``) it counts the components found. ``freedom``
    says in words what is free; ``mechanism`` names a freedom that is no Hervé family
    (a higher pair: ``point-in-plane``, ``point-on-line``, ``planar-point-on-line``,
    ``line-on-plane``, ``roll-and-slide``; :data:`MECHANISMS`).
    """

    body: str
    situation: str
    pose: np.ndarray
    dof: int
    motion: str
    solutions: int | None = 1
    alternatives: tuple[np.ndarray, ...] = ()
    invariants: Mapping[str, Any] = field(default_factory=dict)
    freedom: str = ""
    mechanism: str = ""

    def __post_init__(self) -> None:
        if self.motion not in MOTIONS:
            raise ValueError(f"unknown motion {self.motion!r}")

    @property
    def key(self) -> str:
        """The instance name ``"<body>@<situation>"``."""
        return f"{self.body}@{self.situation}"

    def __repr__(self) -> str:
        from assemblykit import formatting as fmt

        return fmt.summary("BodyInstanceResult", self.key, self.motion, f"{self.dof} dof")

    def to_dict(self) -> dict[str, Any]:
        """The JSON object of docs/tutorial.md, "JSON" for this instance."""
        return {
            "pose": _plain(np.asarray(self.pose, dtype=np.float64)),
            "dof": int(self.dof),
            "motion": self.motion,
            "solutions": "infinite" if self.solutions is None else int(self.solutions),
            "alternatives": [_plain(np.asarray(a, dtype=np.float64)) for a in self.alternatives],
            "invariants": {
                k: _plain(np.asarray(v, dtype=np.float64) if k != "pitch" else float(v))
                for k, v in self.invariants.items()
                if k in INVARIANT_KEYS
            },
            **({"freedom": self.freedom} if self.freedom else {}),
            **({"mechanism": self.mechanism} if self.mechanism else {}),
        }


def point_text(point: Any) -> str:
    """``(0.5, 1, 1.5)``: a point or direction as people write it (tiny values as 0)."""
    from assemblykit import formatting as fmt

    return fmt.vector(np.asarray(point, dtype=np.float64))


MECHANISMS: dict[str, str] = {
    Mechanism.POINT_IN_PLANE: "can slide its point {point} in the plane normal to {normal}"
    " and turn about it",
    Mechanism.POINT_ON_LINE: "can slide its point {point} along {direction} and turn about it",
    Mechanism.PLANAR_POINT_ON_LINE: "can slide its point {point} along {direction} and turn"
    " about {normal} through it",
    Mechanism.LINE_ON_PLANE: "keeps its line through {point} along {direction} parallel to"
    " the plane normal to {normal}: it can slide in the plane and turn about the normal and"
    " about the line",
    Mechanism.ROLL_AND_SLIDE: "can turn about its line through {point} along {direction} and"
    " slide that line sideways, keeping it parallel to the plane normal to {normal}",
}
"""The freedoms of higher pairs that are no Hervé family, in words (the ``mechanism``
names of :class:`BodyInstanceResult`; the placeholders are their invariants)."""


def freedom_words(motion: str, dof: int, invariants: Mapping[str, Any], mechanism: str = "") -> str:
    """What remains free, in words, after the instance's name: ``"can turn about (0.5, 1,
    1.5): 3 dof"``; empty for a fixed instance. A named ``mechanism`` says its freedom
    (:data:`MECHANISMS`); one that the reduction does not name (a closed loop, a coupled
    joint, a relation that is no coset) says its dof."""
    inv = {k: invariant_text(k, v) for k, v in invariants.items() if k != "pitch"}
    if dof and mechanism in MECHANISMS:
        return f"{MECHANISMS[mechanism].format(**inv)}: {dof} dof"
    phrases = {
        "revolute": "turn about the axis through {point} along {direction}",
        "prismatic": "slide along {direction}",
        "helical": "screw about the axis through {point} along {direction}",
        "cylindrical": "slide along and turn about the axis through {point} along {direction}",
        "planar": "slide in the plane normal to {normal} and turn about that normal",
        "spherical": "turn about {center}",
        "translation2": "slide in the plane normal to {normal}",
        "translation3": "slide in every direction",
        "schoenflies": "slide in every direction and turn about {direction}",
        "free": "move freely",
    }
    phrase = phrases.get(motion)
    if dof == 0:
        return ""
    if phrase is None:
        return (
            f"keeps {dof} dof that no joint names (a closed loop, a chain of joints whose"
            " product is no group, or a relation no coset holds)"
        )
    try:
        text = phrase.format(**inv)
    except KeyError:
        return f"moves as a {motion} joint: {dof} dof"
    return f"can {text}: {dof} dof"


_REMEDIES = {
    "revolute": "a stop against the turn (an against or point_on_plane off that axis)",
    "prismatic": "a stop across {direction} (an against or point_on_plane on a face not"
    " parallel to it)",
    "helical": "a stop off that axis (the slide follows the turn)",
    "cylindrical": "an against on a face normal to the axis (the slide) and a stop off it"
    " (the turn)",
    "planar": "three stops in the plane (against or point_on_plane on faces across it, one"
    " off the line of the other two)",
    "spherical": "a fits or coaxial through {center} (leaving a turn about that axis) and a"
    " stop off that axis",
    "translation2": "two stops across the plane's directions (against or point_on_plane)",
    "translation3": "three against relations on faces of independent normals",
    "schoenflies": "an against on a face normal to {direction} and three stops in its plane",
    "pseudo-planar": "an against on a face normal to the axis and two stops in its plane",
    "free": "a fixed relation (or three against relations on faces of independent normals)",
    "point-in-plane": "two more point_on_plane on the same point (making a spherical joint)"
    " and relations on the body's orientation",
    "point-on-line": "a point_on_plane on the same point across the line (making a spherical"
    " joint) and relations on the body's orientation",
    "planar-point-on-line": "a point_on_plane on the same point across {direction} (making"
    " a revolute about {normal}) and a stop off that axis",
    "line-on-plane": "a second point of the body on the plane (the turn about the line) and"
    " stops in the plane (the slides and the turn about {normal})",
    "roll-and-slide": "a stop against the slide (an against or point_on_plane on a face whose"
    " normal leaves the plane of {direction} and {normal}) and a stop off the line (the turn"
    " about it)",
}


def remedy_words(motion: str, mechanism: str, invariants: Mapping[str, Any]) -> str:
    """Which relations would remove the freedom of a ``motion`` (or of a named
    ``mechanism``), in words: ``"a fits or coaxial through (0.5, 1, 1.5) (leaving a turn
    about that axis) and a stop off that axis would remove it"``. A mechanism without a
    name (a closed loop, a coupled joint, a relation that is no coset, solved
    numerically) loses at most one dof to each stop on it or on a body it moves with."""
    inv = {k: invariant_text(k, v) for k, v in invariants.items() if k != "pitch"}
    phrase = _REMEDIES.get(mechanism or motion, "")
    try:
        phrase = phrase.format(**inv)
    except KeyError:
        phrase = ""
    if not phrase:
        return "a stop on it or on a body it moves with would remove one dof"
    return f"{phrase} would remove it"


@dataclass(frozen=True)
class Conflict:
    """Relations that cannot hold together, the kind of mismatch and its size.

    ``needed_tolerance`` is the relative tolerance (``--tolerance``, the angle following
    it) at which the mismatch is accepted, when it is within ``NEARLY_CONSISTENT`` times
    the tolerance in force (:meth:`Tolerance.needed`); ``None`` otherwise."""

    relations: tuple[str, ...]
    kind: str
    value: float
    message: str
    needed_tolerance: float | None = None
    support: tuple[str, ...] = field(default=(), compare=False, repr=False)
    """The statements the conflict was derived from (``relations`` and those that merged
    their instances), which :mod:`assemblykit.inference.conflicts` narrows to the fewest
    that still conflict; not part of the JSON."""

    @classmethod
    def measured(
        cls, relations: tuple[str, ...], kind: str, value: float, message: str, tol: Tolerance
    ) -> Conflict:
        """A conflict whose ``needed_tolerance`` is computed from the mismatch and ``tol``."""
        return cls(relations, kind, value, message, tol.needed(kind, value))

    @property
    def advice(self) -> str | None:
        """The sentence telling how far to loosen the tolerance, when nearly consistent."""
        if self.needed_tolerance is None:
            return None
        t = f"{self.needed_tolerance:.2g}"
        return f"nearly consistent: loosen the tolerance to {t} (--tolerance {t})"

    def to_dict(self) -> dict[str, Any]:
        """``{relations, kind, value, message, needed_tolerance}``."""
        return {
            "relations": list(self.relations),
            "kind": self.kind,
            "value": float(self.value),
            "message": self.message,
            "needed_tolerance": self.needed_tolerance,
        }


@dataclass(frozen=True)
class TraceStep:
    """One reduction rule fired: which rule, on which link, dof before and after."""

    rule: str
    link: str
    dof_before: int | None
    dof_after: int | None
    detail: str = ""

    def to_dict(self) -> dict[str, Any]:
        """``{rule, link, dof_before, dof_after, detail}``."""
        return {
            "rule": self.rule,
            "link": self.link,
            "dof_before": self.dof_before,
            "dof_after": self.dof_after,
            "detail": self.detail,
        }


@dataclass(frozen=True)
class BranchCut:
    """A search over finite alternatives (rule 3) that stopped at its limit: ``followed``
    branches were followed to the end, ``not_followed`` alternatives were not, so the
    solution counts are lower bounds."""

    followed: int
    not_followed: int
    limit: int

    @property
    def message(self) -> str:
        return (
            f"only {self.followed} branches were followed (limit {self.limit}); "
            f"{self.not_followed} alternatives were not: solution counts are lower bounds "
            "(raise --max-branches to follow more)"
        )

    def to_dict(self) -> dict[str, Any]:
        return {
            "followed": self.followed,
            "not_followed": self.not_followed,
            "limit": self.limit,
            "message": self.message,
        }


def direction_text(direction: Any) -> str:
    """``+Z`` for a direction along a coordinate axis, else ``(0.6, 0.8, 0)``."""
    from assemblykit import formatting as fmt

    return fmt.direction(np.asarray(direction, dtype=np.float64))


def invariant_text(key: str, value: Any) -> str:
    """An invariant for people: directions and normals as ``+Z`` where they are axes,
    points as ``(x, y, z)``, the pitch as a number (tiny values shown as 0)."""
    from assemblykit import formatting as fmt

    if key == "pitch":
        return fmt.number(float(value))
    if key in ("direction", "normal"):
        return direction_text(value)
    return fmt.vector(np.asarray(value, dtype=np.float64))


def status_of(
    bodies: Mapping[str, BodyInstanceResult],
    conflicts: tuple[Conflict, ...],
    cut: BranchCut | None = None,
) -> Status:
    """Inconsistent if anything conflicts; ambiguous if some instance has finitely many
    poses (or alternatives were left unexplored); underconstrained if some instance keeps
    freedom (dof > 0 or a lattice)."""
    if conflicts:
        return Status.INCONSISTENT
    if cut is not None or any(
        b.solutions is not None and b.solutions > 1 and b.dof == 0 for b in bodies.values()
    ):
        return Status.AMBIGUOUS
    if any(b.dof > 0 or b.solutions is None for b in bodies.values()):
        return Status.UNDERCONSTRAINED
    return Status.SOLVED


@dataclass(frozen=True)
class Solution:
    """Poses of every body instance, the conflicts found, (on request) the trace, and
    ``cut`` when the search over finite alternatives stopped at its limit.

    When the task is inconsistent, ``valid_without`` names the statements without which
    the poses and freedoms hold: those of the conflicts (docs/inference.md, "Conflicts")."""

    bodies: Mapping[str, BodyInstanceResult]
    conflicts: tuple[Conflict, ...] = ()
    trace: tuple[TraceStep, ...] = ()
    explain: bool = False
    cut: BranchCut | None = None
    units: str | None = None
    valid_without: tuple[str, ...] = ()

    @property
    def status(self) -> Status:
        """``solved``, ``ambiguous``, ``underconstrained`` or ``inconsistent``."""
        return status_of(self.bodies, self.conflicts, self.cut)

    def __getitem__(self, key: str) -> BodyInstanceResult:
        return self.bodies[key]

    def __contains__(self, key: object) -> bool:
        return key in self.bodies

    def __iter__(self) -> Iterator[str]:
        """The instance names ``"<body>@<situation>"``, as a mapping iterates."""
        return iter(self.bodies)

    def __repr__(self) -> str:
        from assemblykit import formatting as fmt

        return fmt.summary(
            "Solution",
            self.status,
            fmt.count(len(self.bodies), "body instance"),
            fmt.count(len(self.conflicts), "conflict"),
        )

    def _repr_html_(self) -> str:
        """The instances as a table: dof, motion, position (notebooks)."""
        from assemblykit import formatting as fmt

        rows = [
            (key, str(b.dof), b.motion, fmt.vector(np.asarray(b.pose)[:3, 3]))
            for key, b in self.bodies.items()
        ]
        return fmt.html_summary(repr(self), ("instance", "dof", "motion", "position"), rows)

    @property
    def suggested_tolerance(self) -> float | None:
        """The loosest tolerance any conflict needs, when every conflict is nearly
        consistent (a looser tolerance may reveal conflicts the first ones hid)."""
        needed = [c.needed_tolerance for c in self.conflicts]
        if not needed or any(n is None for n in needed):
            return None
        return max(n for n in needed if n is not None)

    def to_dict(self) -> dict[str, Any]:
        """The ``solve`` JSON of docs/tutorial.md, "JSON" (plus ``suggested_tolerance`` and
        ``valid_without`` when inconsistent and ``trace`` when explaining)."""
        out: dict[str, Any] = {
            "status": self.status,
            "bodies": {key: b.to_dict() for key, b in self.bodies.items()},
            "conflicts": [c.to_dict() for c in self.conflicts],
        }
        if self.conflicts:
            out["suggested_tolerance"] = self.suggested_tolerance
            out["valid_without"] = list(self.valid_without)
        if self.cut is not None:
            out["truncated"] = self.cut.to_dict()
        if self.explain:
            out["trace"] = [step.to_dict() for step in self.trace]
        return out
