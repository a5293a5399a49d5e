"""Products of cosets along a chain of links that are cosets again (docs/algebra.md §5.3;
docs/inference.md, "Joints made by chains").

The poses along a chain of links H₁x₁·H₂x₂·…·Hₙxₙ are the product set K₁K₂…Kₙ·x with
x = x₁x₂…xₙ and every group carried to the chain's start, Kᵢ = pᵢHᵢpᵢ⁻¹ with
pᵢ = x₁…xᵢ₋₁. Neighbouring groups are joined, from the left, by two rules that keep
the set (Hervé 1999: the product of mechanical bonds):

* two neighbours whose product is a group become that group (one contains the other, or
  the product is a group of the docs/algebra.md §5.3 table: R·P along the axis is C,
  P·P is T₂, T₂·R about its normal is G, ...);
* three revolutes about axes through one point N, the middle axis perpendicular to the
  other two, become the spherical group S(N): every rotation about N is such a product
  (Davenport 1973; docs/algebra.md §5.3: turns about axes e₁, e₂, e₃ reach every
  rotation exactly when e₂ ⊥ e₁ and e₂ ⊥ e₃; Euler's angles are the case e₃ = e₁). With
  a middle axis not perpendicular to both, the product is a proper part of S(N): no
  group.

A chain that joins into one group is that group's coset; otherwise it stays a
:class:`Chain` (of the joined groups when some joined).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from assemblykit.algebra import Chain, Coset, Kind, SymmetryGroup
from assemblykit.tolerance import ModelTolerance


def _joined(
    first: SymmetryGroup, second: SymmetryGroup, tol: ModelTolerance
) -> SymmetryGroup | None:
    """The group ``first·second`` when the product of the two groups is one."""
    found = Coset(first, np.eye(4)).product(Coset(second, np.eye(4)), tol)
    return found.group if isinstance(found, Coset) else None


def _spherical(
    first: SymmetryGroup, middle: SymmetryGroup, last: SymmetryGroup, tol: ModelTolerance
) -> SymmetryGroup | None:
    """S(N) when three connected revolutes turn about axes through one point N with the
    middle axis perpendicular to the other two (docs/algebra.md §5.3), else None."""
    groups = (first, middle, last)
    if any(g.kind != Kind.REVOLUTE or not g.is_connected for g in groups):
        return None
    u1, u2, u3 = (g.axis for g in groups)
    if abs(float(u1 @ u2)) > tol.angle or abs(float(u2 @ u3)) > tol.angle:
        return None
    if np.linalg.norm(np.cross(u1, u2)) <= tol.angle:
        return None
    # the point where the first two axes meet: their common perpendicular's foot
    p1, p2 = first.origin, middle.origin
    normal = np.cross(u1, u2)
    gap = p2 - p1
    if abs(float(gap @ normal)) / float(np.linalg.norm(normal)) > tol.length:
        return None
    along = np.linalg.lstsq(np.column_stack((u1, -u2)), gap, rcond=None)[0]
    center = p1 + along[0] * u1
    offset = center - last.origin
    if np.linalg.norm(offset - (offset @ u3) * u3) > tol.length:
        return None
    return SymmetryGroup.spherical(center)


def _push(stack: list[SymmetryGroup], group: SymmetryGroup, tol: ModelTolerance) -> None:
    """Put ``group`` on the stack of joined groups and join the top while a rule of the
    module docstring applies."""
    stack.append(group)
    while True:
        if len(stack) >= 2:
            joined = _joined(stack[-2], stack[-1], tol)
            if joined is not None:
                stack[-2:] = [joined]
                continue
        if len(stack) >= 3:
            joined = _spherical(stack[-3], stack[-2], stack[-1], tol)
            if joined is not None:
                stack[-3:] = [joined]
                continue
        return


def _at_start(factors: Sequence[Coset]) -> tuple[list[SymmetryGroup], np.ndarray]:
    """The groups of ``factors`` carried to the chain's start, Kᵢ = pᵢHᵢpᵢ⁻¹, and the
    product x of the representatives."""
    prefix = np.eye(4)
    groups: list[SymmetryGroup] = []
    for factor in factors:
        same = np.array_equal(prefix, np.eye(4))
        groups.append(factor.group if same else factor.group.conjugate(prefix))
        prefix = prefix @ factor.rep
    return groups, prefix


def _as_set(stack: list[SymmetryGroup], rep: np.ndarray) -> Coset | Chain:
    """The set K₁…Kₙ·x of joined groups: a coset for one group, else a chain whose
    representatives are all I but the last."""
    if len(stack) == 1:
        return Coset(stack[0], rep)
    return Chain((*(Coset(g, np.eye(4)) for g in stack[:-1]), Coset(stack[-1], rep)))


def chain_product(factors: Sequence[Coset], tol: ModelTolerance) -> Coset | Chain:
    """The product set of the cosets ``factors`` in order: a coset when the chain joins
    into one group (module docstring), else a :class:`Chain` of the groups joined."""
    groups, rep = _at_start(factors)
    stack: list[SymmetryGroup] = []
    for group in groups:
        _push(stack, group, tol)
    return _as_set(stack, rep)


def extend(above: Coset | Chain | None, link: Coset, tol: ModelTolerance) -> Coset | Chain:
    """The poses along a chain that ends with ``link``: ``above`` (the chain so far, as
    this module leaves it, None at its start) times ``link``. Only the new group is
    joined: the groups of ``above`` are joined already."""
    if above is None:
        return link
    stack, rep = _at_start(above.factors if isinstance(above, Chain) else (above,))
    _push(stack, link.group.conjugate(rep), tol)
    return _as_set(stack, rep @ link.rep)
