"""What the programs of an assembly's states found, kept for the states asked about next.

A plan asks about hundreds of states that differ from one already decided by a block
taken away, a part held or the friction coefficient (docs/planning.md, "Under gravity":
the states a plan asks about; the programs are those of rigid-block equilibrium,
Whiting, Ochsendorf and Durand 2009). The balances and Farkas certificates found before
answer many of them with no program, or from a few parts' equations; a piece of a state
that no removal since has touched keeps its residuals; and consecutive states mostly
need the same friction, where the search for the least one starts. Whoever asks the
series of questions creates one :class:`EquilibriumMemory` and passes it to each
(:class:`~assemblykit.planning.equilibrium.EquilibriumModel`): what it keeps changes
which programs are solved, never a verdict.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from assemblykit.planning.kept import Kept

KEPT = 8
"""How many balances an :class:`EquilibriumMemory` keeps (the most recently useful
first) to decide later states without a program: a balance rarely outlives the state it
was found for (removing a block unbalances its neighbours), but decides the friction
coefficients above the one it was found at."""

KEPT_RESIDUALS = 256
"""How many pieces' residuals an :class:`EquilibriumMemory` keeps
(:meth:`~assemblykit.planning.equilibrium.EquilibriumModel.slack`, the oldest forgotten
first): a piece of a state that no removal since has touched has the same ones."""

KEPT_CERTIFICATES = 128
"""How many Farkas certificates an :class:`EquilibriumMemory` keeps (the most recently
useful first): a certificate outlives many states (what falls at one step still falls
at the next, unless its parts are taken or held), and a plan's step finds a few dozen,
one per candidate that falls, most of them asked about again at the next step."""

ResidualKey = tuple[bytes, bytes, float]
"""A piece of a state, the state's immobile parts (both boolean vectors over the parts,
as bytes) and the friction coefficient."""


@dataclass(frozen=True, eq=False)
class KeptBalance:
    """A balance found, as the force at every point (``forces``: normal, ``u`` and ``v``
    parts, P x 3) with the pyramid gauge of its tangential part (``gauge``, P: ``mu``
    times the normal part must reach it), so that one balance serves every friction
    coefficient whose pyramids hold its forces."""

    forces: NDArray[np.float64]
    gauge: NDArray[np.float64]


class EquilibriumMemory:
    """The balances, certificates and residuals found for the states of one model, and
    where its next search for the least friction starts (module docstring)."""

    def __init__(self) -> None:
        self.balances: Kept[int, KeptBalance] = Kept(KEPT)
        """Balances found by the first program, numbered in the order found (the most
        recently useful first)."""
        self.certificates: Kept[int, NDArray[np.float64]] = Kept(KEPT_CERTIFICATES)
        """Farkas certificates found, numbered in the order found (the most recently
        useful first), each as its ``y`` over every equation, zero on those it does not
        weigh."""
        self.residuals: Kept[ResidualKey, NDArray[np.float64]] = Kept(KEPT_RESIDUALS)
        """The residuals of pieces of states, per :data:`ResidualKey` (none is kept
        again: the oldest is forgotten first)."""
        self.reference: KeptBalance | None = None
        """A balance of the state the first states asked about are taken from (a plan's
        whole assembly), kept apart from :attr:`balances`: it only tells where a state
        taken from that one is left unbalanced, the region whose equations alone may
        prove that state falls
        (:meth:`~assemblykit.planning.equilibrium.EquilibriumModel.stands`), until a
        balance is kept; it never shows a state to stand, so it changes no verdict and
        no friction a balance shows."""
        self.bracket_end: int | None = None
        """The upper end of the last bracket of
        :meth:`~assemblykit.planning.equilibrium.EquilibriumModel.friction_needed`, in
        steps of its resolution, where its next search starts (``None``: at the model's
        friction)."""
        self._numbers = itertools.count()
        """The numbers of the balances and certificates, in the order found."""
        self._stacked: tuple[tuple[int, ...], NDArray[np.float64]] | None = None
        """The certificates kept, in increasing number, as the columns of one matrix
        (:meth:`stacked_certificates`), with their numbers."""

    def keep_balance(self, balance: KeptBalance) -> None:
        """Keep a balance just found, first."""
        self.balances.keep(next(self._numbers), balance)

    def keep_certificate(self, certificate: NDArray[np.float64]) -> None:
        """Keep a certificate just found (its ``y`` over every equation), first."""
        self.certificates.keep(next(self._numbers), certificate)

    def stacked_certificates(self) -> tuple[tuple[int, ...], NDArray[np.float64]]:
        """The numbers of the certificates kept, increasing, and the certificates as the
        columns of one matrix in that order: made again only when a certificate is kept
        or forgotten, not when one is used (every state a plan asks about tests them
        all at once)."""
        numbers = tuple(sorted(number for number, _ in self.certificates.items()))
        if self._stacked is None or self._stacked[0] != numbers:
            columns = [self.certificates[number] for number in numbers]
            self._stacked = (numbers, np.stack(columns, axis=1))
        return self._stacked

    def latest_balance(self) -> KeptBalance:
        """The balance kept or used last."""
        return self.balances.first()[1]

    def use_balance(self, number: int, balance: KeptBalance) -> None:
        """Put the balance ``number`` first, as ``balance`` (what it is in the state it
        has just shown to stand)."""
        self.balances.keep(number, balance)

    def improve_latest_balance(self, balance: KeptBalance) -> None:
        """Replace the balance kept or used last by ``balance`` (it stays first)."""
        self.balances.keep(self.balances.first()[0], balance)

    def use_certificate(self, number: int) -> None:
        """Put the certificate ``number`` first: it has just proved a state falls."""
        self.certificates.keep(number, self.certificates[number])
