"""Intersection of symmetry groups with discrete parts (ALGEBRA.md §2.4 "Finite parts").

The connected parts and cyclic lattices meet in closed form
(:mod:`assemblykit.algebra.connected_meets`); the finite components of A = A0 . Gamma_A
and B = B0 . Gamma_B meet pairwise as cosets A0 alpha ∩ B0 beta of the connected parts
(§2.5), each empty or a coset of A0 ∩ B0 whose representative is a component of A ∩ B.
"""

from __future__ import annotations

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
    """G ∩ G' (ALGEBRA.md §2.4): the connected part, the helical residue and the finite
    parts, these met as cosets of the connected parts (§2.5)."""
    tol = tol or current()
    if a.is_connected and b.is_connected:
        return connected_meet(a, b, tol)
    if a.lattice or b.lattice:
        return lattice_meet(a, b, tol)
    c0 = connected_meet(a.connected_part, b.connected_part, tol)
    found: list[NDArray[np.float64]] = []
    for x in a.reps:
        for y in b.reps:
            met = Coset(a.connected_part, x).intersect(Coset(b.connected_part, y), tol)
            if isinstance(met, EmptySet):
                continue
            found.append(met.rep)
    if not found:
        return c0
    return c0.with_known_discrete(reps=tuple(found), lattice=c0.lattice, tol=tol)
