"""Closed-form coset intersections per second (docs/algebra.md §2.5), one core.

Relation cosets are built with ``transporter`` from plane, line (cylinder) and point
(sphere) invariants in random placements, each pair holding at one random relative
pose (consistent, so the answer is a coset), then intersected. Prints the median
rate (CPU time of this process, so other load on the machine does not count) over
repeats for each relation pair, for fresh cosets (cold: nothing derived is cached yet)
and for the same cosets intersected again (warm); the target is >= 10,000 per second.
The thread rows (a helical coset against a plane or cylinder relation) measure the
exact helical intersections of docs/algebra.md §2.4-§2.5, which need no numeric search.
"""

from __future__ import annotations

import statistics
import time

import numpy as np

from assemblykit.algebra import (
    Coset,
    LineInvariant,
    PlaneInvariant,
    PointInvariant,
    SymmetryGroup,
    se3,
    transform_invariant,
    transporter,
)

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


if __name__ == "__main__":
    main()
