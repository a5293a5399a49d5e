"""Exploded views of a disassembly plan, sized by the parts that move.

Frame 0 is the assembly; frame k follows step k. The parts of step t translate along the
step's direction by ``D_t``: ``EXPLODE_CLEARANCE`` times the extent of the moved parts
along that direction, the straight translation that takes a set just clear of where it
was (Wilson & Latombe 1992, "extended translations": the path is free, so once the set has
moved by its own length along ``d`` it no longer overlaps its old place). Parts removed
earlier keep moving away with every later step (their offset in frame k is the sum of
``D_s..D_k``), so the removed parts never close in on the rest, and the whole exploded
view spans about the sum of the moved lengths: a 500-block dome stays as compact as a
gearbox, where a fixed distance per step would spread it over dozens of diameters.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:
    from assemblykit.model.assembly import Assembly
    from assemblykit.planning.plan_values import Plan

EXPLODE_CLEARANCE = 1.25
"""A step moves its parts by this multiple of their extent along the step's direction."""

MIN_EXPLODE_FRACTION = 0.03
"""Smallest move of a step, as a fraction of the assembly's size (so thin parts still
visibly leave)."""


@dataclass(frozen=True)
class Explosion:
    """The offsets of every frame: ``step_of[name]`` is the (1-based) step that moves the
    part (0 for parts no step moves), ``directions[t - 1]`` the unit direction of step t,
    ``travel[k]`` the summed distances of steps 1..k (``travel[0] = 0``)."""

    names: tuple[str, ...]
    step_of: dict[str, int]
    directions: NDArray[np.float64]
    travel: NDArray[np.float64]

    @property
    def frames(self) -> int:
        """Number of frames: the assembly and one per step."""
        return len(self.travel)

    def distance(self, step: int) -> float:
        """How far the parts of ``step`` (1-based) move in their own frame."""
        return float(self.travel[step] - self.travel[step - 1])

    def offset(self, name: str, frame: int) -> NDArray[np.float64]:
        """The translation of part ``name`` in ``frame``."""
        step = self.step_of[name]
        if step == 0 or step > frame:
            return np.zeros(3)
        return self.directions[step - 1] * (self.travel[frame] - self.travel[step - 1])

    def offsets(self, frame: int) -> dict[str, NDArray[np.float64]]:
        """Every part's translation in ``frame``."""
        return {name: self.offset(name, frame) for name in self.names}


def extent_along(points: NDArray[np.float64], direction: Sequence[float]) -> float:
    """Length of the projection of ``points`` on the unit ``direction``."""
    heights = np.asarray(points, dtype=np.float64) @ np.asarray(direction, dtype=np.float64)
    return float(heights.max() - heights.min()) if len(heights) else 0.0


def room(
    box: NDArray[np.float64], within: NDArray[np.float64], direction: NDArray[np.float64]
) -> float:
    """How far ``box`` (``[lo, hi]``) can translate along the unit ``direction`` before
    it leaves the box ``within`` (0 when it is already outside)."""
    lo, hi = box
    limits = [
        ((within[1][i] - hi[i]) if d > 0 else (within[0][i] - lo[i])) / d
        for i, d in enumerate(direction)
        if d != 0
    ]
    return max(min(limits), 0.0) if limits else float("inf")


def explosion(
    assembly: Assembly,
    plan: Plan,
    within: NDArray[np.float64] | None = None,
    reserve: float = 0.0,
) -> Explosion:
    """The exploded frames of ``plan`` over ``assembly`` (module docstring). With a box
    ``within``, a step's parts move no further than keeps them (and ``reserve`` more
    along the direction, room for an arrow) inside it, so the step on show stays in a
    view fitted to the assembly.

    >>> import numpy as np, trimesh
    >>> from assemblykit.model.assembly import Assembly, Part
    >>> from assemblykit.planning.plan_values import Plan, Step
    >>> base = trimesh.creation.box(extents=(4, 4, 1))
    >>> lid = trimesh.creation.box(extents=(2, 2, 2)).apply_translation((0, 0, 1.5))
    >>> assembly = Assembly([Part("base", base), Part("lid", lid)])
    >>> step = Step(("lid",), np.array([0.0, 0.0, 1.0]), ("base",), ())
    >>> frames = explosion(assembly, Plan(("base", "lid"), (step,), (), None, 1))
    >>> frames.offset("lid", 1).tolist()  # 1.25 x the lid's height of 2
    [0.0, 0.0, 2.5]
    """
    smallest = MIN_EXPLODE_FRACTION * assembly.scale
    step_of = dict.fromkeys(assembly.names, 0)
    directions, distances = [], []
    for number, step in enumerate(plan.steps, start=1):
        d = np.asarray(step.direction, dtype=np.float64)[:3]
        d = np.r_[d, np.zeros(3 - len(d))]
        points = np.concatenate([assembly.parts[name].mesh.vertices for name in step.parts])
        distance = EXPLODE_CLEARANCE * extent_along(points, d)
        if within is not None:
            box = np.array([points.min(axis=0), points.max(axis=0) + np.maximum(d, 0) * reserve])
            box[0] += np.minimum(d, 0) * reserve
            distance = min(distance, room(box, within, d))
        distances.append(max(distance, smallest))
        directions.append(d)
        for name in step.parts:
            step_of[name] = number
    return Explosion(
        tuple(assembly.names),
        step_of,
        np.reshape(np.asarray(directions, dtype=np.float64), (-1, 3)),
        np.concatenate([[0.0], np.cumsum(distances)]),
    )
