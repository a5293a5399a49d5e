"""The algebra of assemblykit (layer 0): SE(3), Hervé's symmetry subgroups, cosets,
characteristic invariants and transporters (ALGEBRA.md §1-§2, §5)."""

from assemblykit.algebra.cosets import (
    Chain,
    Coset,
    EmptySet,
    Mismatch,
    intersect_groups,
    stabilizer,
    transporter,
)
from assemblykit.algebra.invariants import (
    DirectionInvariant,
    Invariant,
    LineInvariant,
    PlaneInvariant,
    PointInvariant,
    congruence_mismatch,
    pair_frame,
    transform_invariant,
)
from assemblykit.algebra.subgroups import Kind, Locus, SymmetryGroup

__all__ = [
    "Chain",
    "Coset",
    "DirectionInvariant",
    "EmptySet",
    "Invariant",
    "Kind",
    "LineInvariant",
    "Locus",
    "Mismatch",
    "PlaneInvariant",
    "PointInvariant",
    "SymmetryGroup",
    "congruence_mismatch",
    "intersect_groups",
    "pair_frame",
    "stabilizer",
    "transform_invariant",
    "transporter",
]
