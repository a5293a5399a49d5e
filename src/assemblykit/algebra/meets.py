"""Intersection of symmetry groups with discrete parts (docs/algebra.md §2.4 "Finite parts").

The connected parts and cyclic lattices meet in closed form
(:mod:`assemblykit.algebra.connected_meets`); the finite components of A = A0 . Gamma_A
and B = B0 . Gamma_B meet pairwise as cosets A0 alpha ∩ B0 beta of the connected parts
(§2.5), each empty or a coset of A0 ∩ B0 whose representative is a component of A ∩ B.
"""

from __future__ import annotations

import itertools

import numpy as np
from numpy.typing import NDArray

from assemblykit.algebra.connected_meets import connected_meet, lattice_meet
from assemblykit.algebra.cosets import Coset, EmptySet
from assemblykit.algebra.groups import SymmetryGroup
from assemblykit.tolerance import Tolerance, current

__all__ = ["intersect_groups"]


def intersect_groups(
    a: SymmetryGroup, b: SymmetryGroup, tol: Tolerance | None = None
) -> SymmetryGroup:
    """G ∩ G' (docs/algebra.md §2.4): the connected part, the helical residue and the finite
    parts, these met as cosets of the connected parts (§2.5)."""
    tol = tol or current()
    if a.is_connected and b.is_connected:
        return connected_meet(a, b, tol)
    if a.lattice or b.lattice:
        return lattice_meet(a, b, tol)
    a0, b0 = a.connected_part, b.connected_part
    c0 = connected_meet(a0, b0, tol)
    found: list[NDArray[np.float64]] = []
    for i, j in _component_pairs(a, b, tol):
        met = Coset(a0, a.reps[i]).intersect(Coset(b0, b.reps[j]), tol)
        if isinstance(met, EmptySet):
            continue
        found.append(met.rep)
    if not found:
        return c0
    return c0.with_known_discrete(reps=tuple(found), lattice=c0.lattice, tol=tol)


def _component_pairs(a: SymmetryGroup, b: SymmetryGroup, tol: Tolerance) -> list[tuple[int, int]]:
    """The pairs (i, j) of components A0 alpha_i, B0 beta_j that may meet, in the order of
    all pairs (docs/algebra.md §2.4 "Finite parts").

    When B0 ⊂ A0, A0 alpha ∩ B0 beta is B0 beta if beta is in A0 alpha and empty
    otherwise, so each beta needs only the components of A near it
    (:meth:`SymmetryGroup.components_near`); likewise when A0 ⊂ B0. Otherwise every pair.
    """
    if a.connected_part.includes(b.connected_part, tol):
        pairs = [(i, j) for j, beta in enumerate(b.reps) for i in a.components_near(beta, tol)]
        return sorted(pairs)
    if b.connected_part.includes(a.connected_part, tol):
        return [(i, j) for i, alpha in enumerate(a.reps) for j in b.components_near(alpha, tol)]
    return list(itertools.product(range(len(a.reps)), range(len(b.reps))))
