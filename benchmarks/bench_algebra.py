"""Closed-form coset intersections per second (ALGEBRA.md §2.5), one core.

Relation cosets are built with ``transporter`` from plane, line (cylinder) and point
(sphere) invariants in random placements, each pair holding at one random relative
pose (consistent, so the answer is a coset), then intersected. Prints the median
rate over repeats for each relation pair; the target is >= 10,000 per second.
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
    def make(kind: str):
        p, d = rng.normal(size=3) * 10, rng.normal(size=3)
        return {"plane": PlaneInvariant(p, d), "cylinder": LineInvariant(p, d)}.get(
            kind, PointInvariant(p)
        )

    out = []
    for _ in range(N_PAIRS):
        # Both relations hold at one random relative pose g: a consistent pair.
        g = se3.random_transform(rng)
        out.append((_relation(make(kinds[0]), g), _relation(make(kinds[1]), g)))
    return out


def main() -> None:
    rng = np.random.default_rng(0)
    print(f"closed-form coset intersections per second ({N_PAIRS} pairs, median of {REPEATS})")
    for kinds in (
        ("plane", "plane"),
        ("plane", "cylinder"),
        ("cylinder", "cylinder"),
        ("sphere", "sphere"),
    ):
        pairs = _pairs(kinds, rng)
        rates = []
        for _ in range(REPEATS):
            start = time.perf_counter()
            for a, b in pairs:
                a.intersect(b)
            rates.append(N_PAIRS / (time.perf_counter() - start))
        rate = statistics.median(rates)
        print(f"  {kinds[0]:>8} / {kinds[1]:<8} {rate:10.0f} /s  ({rate / TARGET:.2f} x target)")


if __name__ == "__main__":
    main()
