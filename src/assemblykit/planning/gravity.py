"""What stability-aware planning is asked and answers: the settings of gravity
(:class:`Gravity`), a state's verdict (:class:`Equilibrium`), a step's
(:class:`StepStability`) and a plan's (:class:`GravityReport`), in the rigid-block
equilibrium of Whiting, Ochsendorf and Durand 2009 ("Procedural modeling of
structurally-sound masonry buildings"; docs/planning.md, "Under gravity").
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from assemblykit import formatting as fmt
from assemblykit.errors import InputError

FRICTION = 0.5
"""Default Coulomb friction coefficient."""

DOWN = (0.0, 0.0, -1.0)
"""Default gravity direction: ``-z``, the convention of block assemblies."""

_AXES = {"x": 0, "y": 1, "z": 2}


def gravity_direction(value: str | ArrayLike) -> NDArray[np.float64]:
    """The unit gravity direction from ``-z``, ``+y``, ``x`` or a vector (``0,0,-1``, a
    sequence of three numbers); :class:`InputError` naming ``--gravity`` otherwise."""
    if isinstance(value, str):
        text = value.strip().lower()
        sign = -1.0 if text.startswith("-") else 1.0
        axis = text.lstrip("+-")
        if axis in _AXES:
            vector = np.zeros(3)
            vector[_AXES[axis]] = sign
            return vector
        try:
            numbers = [float(x) for x in text.replace(",", " ").split()]
        except ValueError:
            numbers = []
    else:
        numbers = [float(x) for x in np.asarray(value, dtype=np.float64).ravel()]
    vector = np.asarray(numbers, dtype=np.float64)
    norm = float(np.linalg.norm(vector)) if vector.shape == (3,) else 0.0
    if not (math.isfinite(norm) and norm > 0):
        raise InputError(
            f"expected -z, +y, x or three numbers such as 0,0,-1, got {value!r}", where="--gravity"
        )
    return vector / norm


@dataclass(frozen=True)
class Gravity:
    """The settings of stability-aware planning: unit ``direction`` of gravity,
    ``friction`` coefficient, ``holds`` (hands or fixtures per step, the one holding the
    moved parts included), ``fixed`` parts (``None``: those touching the lowest plane,
    :func:`~assemblykit.model.assembly.lowest_parts`) and per-part ``densities`` (others 1)."""

    direction: tuple[float, float, float] = DOWN
    friction: float = FRICTION
    holds: int = 1
    fixed: tuple[str, ...] | None = None
    densities: tuple[tuple[str, float], ...] = ()

    @property
    def extra_holds(self) -> int:
        """The holds beyond the grip of the moved parts: ``holds - 1``."""
        return self.holds - 1

    def to_dict(self) -> dict[str, Any]:
        """JSON form: ``direction``, ``friction``, ``holds`` (the grip included) and
        ``extra_holds`` (beyond it)."""
        return {
            "direction": [float(x) + 0.0 for x in self.direction],
            "friction": self.friction,
            "holds": self.holds,
            "extra_holds": self.extra_holds,
        }


@dataclass(frozen=True)
class Equilibrium:
    """Whether the parts ``parts`` stand with ``fixed`` parts immobile: ``would_fall``
    lists the free parts that cannot be in equilibrium (residual beyond the tolerance),
    ``residuals`` the largest scaled residual per free part."""

    parts: tuple[str, ...]
    fixed: tuple[str, ...]
    would_fall: tuple[str, ...]
    residuals: tuple[float, ...]

    @property
    def stands(self) -> bool:
        """True when every free part is in equilibrium."""
        return not self.would_fall

    def to_dict(self) -> dict[str, Any]:
        """JSON form: ``stands``, ``parts``, ``fixed``, ``would_fall``."""
        return {
            "stands": self.stands,
            "parts": list(self.parts),
            "fixed": list(self.fixed),
            "would_fall": list(self.would_fall),
        }


def _friction_cell(needed: float | None, tips: bool) -> str:
    """The friction needed as a table cell: the coefficient, or when ``friction`` does
    not suffice "tips" (no friction would hold it) or "more than μ" (more would)."""
    if needed is not None:
        return f"{needed:.3f}"
    return "tips" if tips else "more than μ"


@dataclass(frozen=True)
class StepStability:
    """A disassembly step under gravity: ``held`` are the parts held during it (one grip
    on the moved parts, the grip of a subassembly being taken apart in the air, and the
    parts held so that the rest stands), ``would_fall`` the parts that would fall without
    the holds beyond the grip(s), ``stands`` whether every state stands with the holds
    (within the ``holds`` allowed), ``friction_needed`` the least friction coefficient
    with which they stand (``None`` when ``friction`` does not suffice)."""

    held: tuple[str, ...]
    would_fall: tuple[str, ...]
    stands: bool
    friction_needed: float | None
    friction: float
    unbalanced: float | None = None
    """When the step does not stand: the largest share of a part's weight that no
    balance of the contact forces carries (the slack program's residual, without the
    holds beyond the grips): how far beyond :attr:`threshold` the fall is."""
    threshold: float = 0.0
    """The residual beyond which a part falls (the model's tolerance)."""
    tips: bool = False
    """When ``friction`` does not suffice: whether a state of the step falls even with
    unbounded friction (it tips over; otherwise it slides: more friction would hold it,
    :meth:`~assemblykit.planning.equilibrium.EquilibriumModel.tips`)."""

    @property
    def margin(self) -> float | None:
        """``friction - friction_needed``: how much friction may be lost before the states
        of the step no longer stand (``None`` when they do not)."""
        return None if self.friction_needed is None else self.friction - self.friction_needed

    def to_dict(self) -> dict[str, Any]:
        """JSON keys added to a step: ``held``, ``would_fall``, ``stands``,
        ``friction_needed``, ``stability_margin`` (the friction that may be lost), for
        a step that does not stand ``unbalanced`` with the ``fall_threshold`` it is
        compared to (how far the verdict is from the solver's tolerance), and ``tips``
        (:attr:`tips`)."""
        return {
            "held": list(self.held),
            "would_fall": list(self.would_fall),
            "stands": self.stands,
            "friction_needed": self.friction_needed,
            "stability_margin": self.margin,
            "unbalanced": self.unbalanced,
            "fall_threshold": self.threshold,
            "tips": self.tips,
        }

    def cells(self) -> list[str]:
        """Table cells: held, would fall, friction needed ("tips" when no friction
        holds a state, "more than μ" when more would); long lists of parts cut to their
        first names and how many more, as the plan's "away from" cells are
        (docs/planning.md, "Under gravity")."""
        needed = _friction_cell(self.friction_needed, self.tips)
        return [fmt.name_list(self.held), fmt.name_list(self.would_fall) or "-", needed]


@dataclass(frozen=True)
class GravityReport:
    """A plan's stability: its ``settings``, the ``fixed`` parts, whether the ``whole``
    assembly stands, the least friction it needs, and ``stable``: every state of the plan
    stands with the holds listed."""

    settings: Gravity
    fixed: tuple[str, ...]
    whole: Equilibrium
    friction_needed: float | None
    stable: bool
    tips: bool = False
    """When ``friction`` does not suffice for the whole assembly: whether it falls even
    with unbounded friction (:meth:`~assemblykit.planning.equilibrium.EquilibriumModel.tips`)."""

    def to_dict(self) -> dict[str, Any]:
        """JSON form: the settings, ``fixed``, ``stable``, ``stands``, ``would_fall``
        and ``tips`` (of the whole assembly) and its ``friction_needed``."""
        return {
            **self.settings.to_dict(),
            "fixed": list(self.fixed),
            "stable": self.stable,
            "stands": self.whole.stands,
            "would_fall": list(self.whole.would_fall),
            "tips": self.tips,
            "friction_needed": self.friction_needed,
        }

    def cells(self) -> list[str]:
        """Table cells of the whole assembly as given, as :meth:`StepStability.cells`
        has them: nothing held, the parts that would fall, the friction needed."""
        needed = _friction_cell(self.friction_needed, self.tips)
        return ["-", fmt.name_list(self.whole.would_fall) or "-", needed]

    def summary(self) -> str:
        """One phrase for a table title."""
        extra = self.settings.extra_holds
        holds = "no extra hold" if extra == 0 else fmt.count(extra, "extra hold")
        verdict = "every state stands" if self.stable else "some states fall"
        return f"gravity, μ = {self.settings.friction:g}, {holds}: {verdict}"
