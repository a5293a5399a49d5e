"""RAPT inference (Corner et al. 1983): the relational network of body instances, its reduction by
standard solutions, merges and cycles, and the residue solved numerically."""

from assemblykit.inference.reduction import solve_network, solve_numeric_only, solve_task
from assemblykit.inference.solution import BodyInstanceResult, Conflict, Solution, TraceStep

__all__ = [
    "BodyInstanceResult",
    "Conflict",
    "Solution",
    "TraceStep",
    "solve_network",
    "solve_numeric_only",
    "solve_task",
]
