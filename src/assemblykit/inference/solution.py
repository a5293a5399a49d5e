"""The answer of RAPT inference: a pose set per body instance (DESIGN.md §4, §5.3).

A result that is a set is reported as a set: every body instance ``"<body>@<situation>"``
has a representative pose, its remaining dof and motion group with invariants in world
coordinates, and the number of solutions (with the other poses when there are finitely
many). Inconsistencies are answers, listed as conflicts naming the relations and the
size of the mismatch.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from rich.console import Group
from rich.table import Table
from rich.text import Text

STATUSES = ("solved", "ambiguous", "underconstrained", "inconsistent")

MOTIONS = (
    "fixed",
    "revolute",
    "prismatic",
    "helical",
    "cylindrical",
    "planar",
    "spherical",
    "translation2",
    "translation3",
    "pseudo-planar",
    "schoenflies",
    "free",
    "mechanism",
)

INVARIANT_KEYS = ("point", "direction", "normal", "center", "pitch")


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
    lattice); for a continuum (``dof > 0``) it counts the components found.
    """

    body: str
    situation: str
    pose: np.ndarray
    dof: int
    motion: str
    solutions: int | None = 1
    alternatives: tuple[np.ndarray, ...] = ()
    invariants: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.motion not in MOTIONS:
            raise ValueError(f"unknown motion {self.motion!r}")

    @property
    def key(self) -> str:
        """The instance name ``"<body>@<situation>"``."""
        return f"{self.body}@{self.situation}"

    def to_dict(self) -> dict[str, Any]:
        """The JSON object of DESIGN.md §5.3 for this instance."""
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
        }


@dataclass(frozen=True)
class Conflict:
    """Relations that cannot hold together, the kind of mismatch and its size."""

    relations: tuple[str, ...]
    kind: str
    value: float
    message: str

    def to_dict(self) -> dict[str, Any]:
        """``{relations, kind, value, message}``."""
        return {
            "relations": list(self.relations),
            "kind": self.kind,
            "value": float(self.value),
            "message": self.message,
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


def status_of(bodies: Mapping[str, BodyInstanceResult], conflicts: tuple[Conflict, ...]) -> str:
    """Inconsistent if anything conflicts; ambiguous if some instance has finitely many
    poses; underconstrained if some instance keeps freedom (dof > 0 or a lattice)."""
    if conflicts:
        return "inconsistent"
    if any(b.solutions is not None and b.solutions > 1 and b.dof == 0 for b in bodies.values()):
        return "ambiguous"
    if any(b.dof > 0 or b.solutions is None for b in bodies.values()):
        return "underconstrained"
    return "solved"


@dataclass(frozen=True)
class Solution:
    """Poses of every body instance, the conflicts found and (on request) the trace."""

    bodies: Mapping[str, BodyInstanceResult]
    conflicts: tuple[Conflict, ...] = ()
    trace: tuple[TraceStep, ...] = ()
    explain: bool = False

    @property
    def status(self) -> str:
        """``solved``, ``ambiguous``, ``underconstrained`` or ``inconsistent``."""
        return status_of(self.bodies, self.conflicts)

    def to_dict(self) -> dict[str, Any]:
        """The ``solve`` JSON of DESIGN.md §5.3 (plus ``trace`` when explaining)."""
        out: dict[str, Any] = {
            "status": self.status,
            "bodies": {key: b.to_dict() for key, b in self.bodies.items()},
            "conflicts": [c.to_dict() for c in self.conflicts],
        }
        if self.explain:
            out["trace"] = [step.to_dict() for step in self.trace]
        return out

    def render(self) -> Group:
        """A rich table of instances, then conflicts and (when explaining) the trace."""
        table = Table(title=f"RAPT inference: {self.status}")
        for column in ("instance", "dof", "motion", "solutions", "position", "invariants"):
            table.add_column(column)
        for key, b in self.bodies.items():
            invariants = ", ".join(
                f"{k}={np.round(np.asarray(v, dtype=float), 6).tolist()}"
                for k, v in b.invariants.items()
                if k in INVARIANT_KEYS
            )
            table.add_row(
                key,
                str(b.dof),
                b.motion,
                "infinite" if b.solutions is None else str(b.solutions),
                str(np.round(np.asarray(b.pose)[:3, 3], 6).tolist()),
                invariants,
            )
        parts: list[Any] = [table]
        for c in self.conflicts:
            parts.append(Text(f"conflict ({c.kind} {c.value:.6g}): {', '.join(c.relations)}"))
            parts.append(Text(f"  {c.message}"))
        if self.explain:
            # one line per step whatever the width: the trace is read by people and programs
            for step in self.trace:
                parts.append(
                    Text(
                        f"{step.rule}: {step.link} dof {step.dof_before} -> {step.dof_after}"
                        + (f" ({step.detail})" if step.detail else ""),
                        no_wrap=True,
                        overflow="ignore",
                    )
                )
        return Group(*parts)
