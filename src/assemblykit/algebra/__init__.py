"""The algebra of assemblykit (layer 0): SE(3), Hervé's symmetry subgroups, cosets,
characteristic invariants and transporters (docs/algebra.md §1-§2, §5)."""

from assemblykit.algebra.cosets import Chain, Coset, EmptySet, stabilizer, transporter
from assemblykit.algebra.groups import SymmetryGroup
from assemblykit.algebra.invariants import (
    DirectionInvariant,
    Invariant,
    LineInvariant,
    Mismatch,
    MismatchKind,
    PlaneInvariant,
    PointInvariant,
    congruence_mismatch,
    pair_frame,
    transform_invariant,
)
from assemblykit.algebra.lie import Kind
from assemblykit.algebra.loci import Locus, LocusKind
from assemblykit.algebra.meets import intersect_groups

__all__ = [
    "Chain",
    "Coset",
    "DirectionInvariant",
    "EmptySet",
    "Invariant",
    "Kind",
    "LineInvariant",
    "Locus",
    "LocusKind",
    "Mismatch",
    "MismatchKind",
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
