"""Closed-form coset intersections per second (docs/algebra.md §2.5), one core.

Relation cosets are built with ``transporter`` from plane, line (cylinder) and point
(sphere) invariants in random placements, each pair holding at one random relative
pose (consistent, so the answer is a coset), then intersected. Prints the median
rate (CPU time of this process, so other load on the machine does not count) over
repeats for each relation pair, for fresh cosets (cold: nothing derived is cached yet)
and for the same cosets intersected again (warm); the target is >= 10,000 per second.
The thread rows (a helical coset against a plane or cylinder relation) measure the
exact helical intersections of docs/algebra.md §2.4-§2.5, which need no numeric search.

Then the meets of groups with many components (docs/algebra.md §2.4): prisms of 1000 and
1500 sides, each meet in CPU seconds against its target of 5 s (a meet of every pair of
components takes minutes). The tests check the same answers with 360 sides.
"""

from __future__ import annotations

import math
import statistics
import time

import numpy as np

from assemblykit.algebra import (
    Coset,
    EmptySet,
    Kind,
    LineInvariant,
    PlaneInvariant,
    PointInvariant,
    SymmetryGroup,
    intersect_groups,
    se3,
    transform_invariant,
    transporter,
)

LARGE_TARGET = 5.0
"""CPU seconds each meet of groups with many components may take."""

N_PAIRS = 200
REPEATS = 7
TARGET = 10_000


def _relation(inv, g: np.ndarray) -> Coset:
    out = transporter([inv], [transform_invariant(se3.inverse(g), inv)])
    assert isinstance(out, Coset)
    return out


def _pairs(kinds: tuple[str, str], rng: np.random.Generator) -> list[tuple[Coset, Coset]]:
    def make(kind: str, g: np.ndarray) -> Coset:
        p, d = rng.normal(size=3) * 10, rng.normal(size=3)
        if kind == "thread":
            pitch = float(rng.uniform(0.05, 1.0))
            return Coset(SymmetryGroup.helical(p, d, pitch), g)
        inv = {"plane": PlaneInvariant(p, d), "cylinder": LineInvariant(p, d)}.get(
            kind, PointInvariant(p)
        )
        return _relation(inv, g)

    out = []
    for _ in range(N_PAIRS):
        # Both relations hold at one random relative pose g: a consistent pair.
        g = se3.random_transform(rng)
        out.append((make(kinds[0], g), make(kinds[1], g)))
    return out


def _rate(pairs: list[tuple[Coset, Coset]]) -> float:
    start = time.process_time()
    for a, b in pairs:
        a.intersect(b)
    return len(pairs) / (time.process_time() - start)


def main() -> None:
    rng = np.random.default_rng(0)
    print(
        f"closed-form coset intersections per CPU second on one core ({N_PAIRS} pairs, "
        f"median of {REPEATS}); cold = fresh cosets each round, warm = the same cosets again"
    )
    for kinds in (
        ("plane", "plane"),
        ("plane", "cylinder"),
        ("cylinder", "cylinder"),
        ("sphere", "sphere"),
        ("thread", "plane"),
        ("thread", "cylinder"),
    ):
        cold, warm = [], []
        for _ in range(REPEATS):
            pairs = _pairs(kinds, rng)
            cold.append(_rate(pairs))
            warm.append(_rate(pairs))
        c, w = statistics.median(cold), statistics.median(warm)
        print(
            f"  {kinds[0]:>8} / {kinds[1]:<8} cold {c:8.0f} /s ({c / TARGET:.2f} x target)"
            f"   warm {w:8.0f} /s ({w / TARGET:.2f} x target)"
        )


def prism_coset(sides: int, height: float = 0.0, rep: np.ndarray | None = None) -> Coset:
    """The fit of a prism of ``sides`` sides about the z axis (a vertex on x; the frame
    at ``height``): (T(z) ⋊ Cₙ) . ``rep``, its group listing I and the n - 1 turns."""
    frame = se3.frame((0.0, 0.0, height), (0.0, 0.0, 1.0))
    turns = tuple(
        frame @ se3.rot_z(math.tau * k / sides) @ se3.inverse(frame) for k in range(1, sides)
    )
    group = SymmetryGroup(Kind.PRISMATIC, frame, 0.0, (np.eye(4), *turns))
    return Coset(group, np.eye(4) if rep is None else rep)


def large_groups() -> None:
    """Times the meets of groups of 500-1000 components, each with its answer checked."""
    print(f"meets of groups with many components, CPU s (target <= {LARGE_TARGET:g} s each)")
    z = (0.0, 0.0, 1.0)
    pose = se3.translation((0.3, -0.2, 4.0)) @ se3.rot_z(0.1)
    cases = {
        "C1000 ∩ C1500 = C500": lambda: (
            intersect_groups(
                SymmetryGroup.cyclic((0.0, 0.0, 0.0), z, 1000),
                SymmetryGroup.cyclic((0.0, 0.0, 0.0), z, 1500),
            ).n_components
            == 500
        ),
        "1000-sided prism fit ∩ face contact": lambda: (
            prism_coset(1000).intersect(Coset(SymmetryGroup.planar(z), np.eye(4))).n_components
            == 1000
        ),
        "two coaxial 1000-sided prism fits": lambda: (
            prism_coset(1000, rep=pose)
            .intersect(prism_coset(1000, -20.0, se3.rot_z(math.tau * 7 / 1000) @ pose))
            .n_components
            == 1000
        ),
        "1000-sided fits a third of a step apart": lambda: isinstance(
            prism_coset(1000).intersect(prism_coset(1000, rep=se3.rot_z(math.tau / 3000))),
            EmptySet,
        ),
        "closure of 999 turns over T(z)": lambda: (
            SymmetryGroup.prismatic(z)
            .with_discrete(reps=tuple(se3.rot_z(math.tau * k / 1000) for k in range(1, 1000)))
            .n_components
            == 1000
        ),
    }
    for name, meet in cases.items():
        start = time.process_time()
        right = meet()
        seconds = time.process_time() - start
        verdict = "met" if seconds <= LARGE_TARGET else "NOT met"
        print(f"  {name:42} {seconds:6.2f} s ({verdict}){'' if right else '  WRONG ANSWER'}")


if __name__ == "__main__":
    main()
    large_groups()
