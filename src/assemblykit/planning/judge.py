"""The planner's judge of candidate steps under gravity: which parts a step leaves
falling, which of them are held, whether it stands, and for the step taken the least
friction its states need and whether one of them tips over. Planning assembly as
reversed disassembly that keeps every intermediate state standing, with temporary
supports where it cannot, is the approach of Kao et al. 2017 ("Assembly-aware design of
masonry shell structures"); the states are judged by rigid-block equilibrium (Whiting,
Ochsendorf and Durand 2009; docs/planning.md, "Under gravity").
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numpy.typing import NDArray

from assemblykit.planning.equilibrium import EquilibriumModel
from assemblykit.planning.equilibrium_memory import EquilibriumMemory
from assemblykit.planning.gravity import StepStability
from assemblykit.planning.kept import Kept

State = tuple[bytes, bytes]
"""A state as the bytes of its two boolean vectors over the model's parts: the parts
present and the immobile ones."""


def _state(present: NDArray[np.bool_], fixed: NDArray[np.bool_]) -> State:
    """The key of the state ``present`` with ``fixed`` immobile."""
    return present.tobytes(), fixed.tobytes()


@dataclass(frozen=True)
class _Assessment:
    """A candidate step judged: its holds, its verdict, its two states (what remains and
    what is taken, each with its immobile parts) and, asked for only when needed (a
    slack program each), the parts that would fall without the holds."""

    held: NDArray[np.bool_]
    stands: bool
    states: tuple[tuple[NDArray[np.bool_], NDArray[np.bool_]], ...]
    asked: tuple[tuple[NDArray[np.bool_], NDArray[np.bool_]], ...]
    """The states without the holds whose residuals :attr:`residuals` takes."""
    residual: Callable[[], NDArray[np.float64]]
    """Per part, its residual without the holds (a slack program per state that falls)."""
    threshold: float

    @cached_property
    def residuals(self) -> NDArray[np.float64]:
        """Per part, the share of its weight left unbalanced without the holds."""
        return self.residual()

    @cached_property
    def falls(self) -> NDArray[np.bool_]:
        """The parts that would fall without the holds."""
        return self.residuals > self.threshold


class StateJudge:
    """Stability of the planner's candidate steps (sets of parts as bit masks).

    A step moves ``moved`` out of ``members``. The set on the ground (it holds the
    planner's base, ``ground_base``) keeps the model's fixed parts immobile; a
    subassembly taken away earlier is held by its grip (its base), which costs a hold.
    The moved parts are gripped at their base (one hold) and must stand on it when they
    are several; what remains must stand. Parts that would fall are held greedily,
    highest first, while holds remain (``holds`` in all). ``vector`` turns a mask into a
    boolean vector over the model's parts; ``base`` names a set's base. ``memory`` keeps
    what the model's programs found from one state to the next, and the judge keeps each
    state's verdict and residuals, each step's assessment, and per set of parts the
    single parts whose removal was judged not to stand.
    """

    def __init__(
        self,
        model: EquilibriumModel,
        memory: EquilibriumMemory,
        holds: int,
        vector: Callable[[int], NDArray[np.bool_]],
        base: Callable[[int], int],
        ground_base: int,
    ) -> None:
        self.model = model
        self.memory = memory
        self.holds = holds
        self.vector = vector
        self.base = base
        self.ground_base = ground_base
        self.fixed = model.mask(model.fixed)
        self._stands: Kept[State, bool] = Kept()
        self._residuals: Kept[State, NDArray[np.float64]] = Kept()
        self._assessed: Kept[tuple[int, int], _Assessment] = Kept()
        self._single_falls: Kept[int, int] = Kept()

    def stands(self, present: NDArray[np.bool_], fixed: NDArray[np.bool_]) -> bool:
        """:meth:`EquilibriumModel.stands`, once per state."""
        return self._stands.recall(
            _state(present, fixed), lambda: self.model.stands(present, fixed, memory=self.memory)
        )

    def residual(self, present: NDArray[np.bool_], fixed: NDArray[np.bool_]) -> NDArray[np.float64]:
        """:meth:`EquilibriumModel.residuals`, once per state: the slack program only when
        :meth:`stands` says it does not."""

        def residuals() -> NDArray[np.float64]:
            if self.stands(present, fixed):
                return np.zeros(len(present))
            return self.model.slack(present, fixed, memory=self.memory)

        return self._residuals.recall(_state(present, fixed), residuals)

    def falling(self, present: NDArray[np.bool_], fixed: NDArray[np.bool_]) -> NDArray[np.bool_]:
        """:meth:`EquilibriumModel.falling`, once per state (:meth:`residual`)."""
        return self.residual(present, fixed) > self.model.threshold

    def _hold(
        self, present: NDArray[np.bool_], fixed: NDArray[np.bool_], budget: int
    ) -> tuple[NDArray[np.bool_], bool]:
        """Hold the highest falling part of ``present`` while ``budget`` allows: the
        holds and whether the state then stands (once the last hold is taken, or when
        none may be, which parts still fall no longer matters: the first program alone
        tells)."""
        held = np.zeros_like(present)
        if budget <= 0:
            return held, self.stands(present, fixed)
        now = self.falling(present, fixed)
        while now.any() and int(held.sum()) < budget:
            top = min(np.flatnonzero(now), key=lambda i: (int(self.model.levels[i]), i))
            held[top] = True
            if int(held.sum()) == budget:
                return held, self.stands(present, fixed | held)
            now = self.falling(present, fixed | held)
        return held, not now.any()

    def _one(self, index: int) -> NDArray[np.bool_]:
        """The boolean vector over the model's parts of part ``index`` alone."""
        out = np.zeros(len(self.model.names), dtype=bool)
        out[index] = True
        return out

    def assess(self, members: int, moved: int) -> _Assessment:
        """The holds, falling parts and verdict of moving ``moved`` out of ``members``,
        once per step."""
        key = (members, moved)
        if key not in self._assessed:
            found = self._assessment(members, moved)
            self._assessed.keep(key, found)
            if not found.stands and moved & (moved - 1) == 0:
                self._single_falls.keep(members, self.known_to_fall(members) | moved)
        return self._assessed[key]

    def _assessment(self, members: int, moved: int) -> _Assessment:
        """:meth:`assess`, computed."""
        inside, taken = self.vector(members), self.vector(moved)
        rest = inside & ~taken
        grounded = bool(members >> self.ground_base & 1)
        ground = self.fixed if grounded else self._one(self.base(members))
        grip = self._one(self.base(moved))
        base_held = rest & ground if not grounded else np.zeros_like(rest)
        budget = self.holds - 1 - int(base_held.sum())
        several = int(taken.sum()) > 1
        held_rest, rest_ok = self._hold(rest, rest & ground, budget)
        held_moved, moved_ok = np.zeros_like(rest), True
        if several:
            held_moved, moved_ok = self._hold(taken, grip, budget - int(held_rest.sum()))
        held = grip | base_held | held_rest | held_moved
        asked = ((rest, rest & ground), (taken, grip)) if several else ((rest, rest & ground),)

        def residual() -> NDArray[np.float64]:
            found: NDArray[np.float64] = np.maximum.reduce([self.residual(*s) for s in asked])
            return found

        return _Assessment(
            held=held,
            stands=rest_ok and moved_ok and int(held.sum()) <= self.holds,
            states=((rest, (rest & ground) | held_rest), (taken, grip | held_moved)),
            asked=asked,
            residual=residual,
            threshold=self.model.threshold,
        )

    def ordered(self, sets: list[int]) -> list[int]:
        """Fewest parts first, then the highest (a set's highest centre, to
        :data:`~assemblykit.tolerance.ORDER_RESOLUTION`), then index."""

        def key(mask: int) -> tuple[int, int, int]:
            inside = self.vector(mask)
            return (int(inside.sum()), int(self.model.levels[inside].min()), mask)

        return sorted(sets, key=key)

    def stands_without(self, members: int, moved: int) -> bool:
        """Whether moving ``moved`` out of ``members`` stands with the holds allowed (the
        planner moves the first such set, in :meth:`ordered`, alone)."""
        return self.assess(members, moved).stands

    def known_to_fall(self, members: int) -> int:
        """The parts of ``members`` (a mask) whose removal alone was judged already and
        does not stand (nothing is computed)."""
        return self._single_falls.get(members, 0)

    def fewest_falling(self, members: int, k: int, sets: list[int]) -> list[int]:
        """The set whose removal leaves the fewest parts falling (a step that does not
        stand, reported as such). The slack programs of the states known not to stand
        are solved together first (:meth:`EquilibriumModel.solve_slack`)."""
        ordered = self.ordered(sets)
        falling = [
            state
            for mask in ordered
            for state in self.assess(members, mask).asked
            if not self._stands.get(_state(*state), True)
        ]
        self.model.solve_slack(falling, memory=self.memory)
        return [min(ordered, key=lambda m: int(self.assess(members, m).falls.sum()))]

    def judge(self, members: int, moved: int) -> StepStability:
        """The step's stability, with the least friction its states need and, when
        ``friction`` does not suffice, whether one of them tips over (one program per
        state that falls: :meth:`EquilibriumModel.tips`)."""
        found = self.assess(members, moved)
        names = self.model.names
        states = [(present, fixed) for present, fixed in found.states if (present & ~fixed).any()]
        needed = [
            self.model.friction_needed(
                present, fixed, self.falling(present, fixed), memory=self.memory
            )
            for present, fixed in states
        ]
        tips = any(
            self.model.tips(present, fixed)
            for (present, fixed), need in zip(states, needed, strict=True)
            if need is None
        )
        return StepStability(
            held=tuple(names[i] for i in np.flatnonzero(found.held)),
            would_fall=tuple(names[i] for i in np.flatnonzero(found.falls)),
            stands=found.stands,
            friction_needed=None if None in needed else max(needed, default=0.0),  # type: ignore[type-var]
            friction=self.model.friction,
            unbalanced=None if found.stands else float(found.residuals.max()),
            threshold=self.model.threshold,
            tips=tips,
        )
