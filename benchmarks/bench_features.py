"""Benchmark: feature groups, relation cosets, compound groups and relation residuals.

Run as ``python benchmarks/bench_features.py``; prints medians over repeated runs.
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable

import numpy as np

from assemblykit.algebra import se3
from assemblykit.features import Hole, Plane, Prism, Shaft, Thread, compound_group
from assemblykit.model.relations import relation_coset, relation_residual

Z, MZ = (0, 0, 1), (0, 0, -1)


def median_seconds(work: Callable[[], object], repeat: int = 7, number: int = 20) -> float:
    """The median over ``repeat`` runs of the mean time of one call of ``work``."""
    runs = []
    for _ in range(repeat):
        start = time.perf_counter()
        for _ in range(number):
            work()
        runs.append((time.perf_counter() - start) / number)
    return statistics.median(runs)


def main() -> None:
    pin, bore = Shaft((0, 0, 0), MZ, 5), Hole((0, 0, 0), MZ, 5)
    head, top = Plane((0, 0, 0), MZ), Plane((0, 0, 0), Z)
    bolt = Thread((0, 0, 0), Z, radius=5, lead=1.5)
    nut = Thread((0, 0, 0), Z, radius=5, lead=1.5, male=False)
    spline = Prism((0, 0, 0), Z, sides=24, size=3)
    hub = Prism((0, 0, 0), Z, sides=24, size=3, male=False)
    print("relation cosets (median per call):")
    for label, work in [
        ("against", lambda: relation_coset("against", head, top)),
        ("fits shaft/hole", lambda: relation_coset("fits", pin, bore)),
        ("fits thread", lambda: relation_coset("fits", bolt, nut)),
        ("fits 24-spline", lambda: relation_coset("fits", spline, hub)),
        (
            "fits + against intersect",
            lambda: relation_coset("fits", pin, bore).intersect(
                relation_coset("against", head, top)
            ),
        ),
    ]:
        print(f"  {label:28s} {median_seconds(work) * 1e6:10.1f} us")
    pins = [Shaft((x, y, 0), Z, 1) for x, y in ((1, 1), (-1, 1), (-1, -1), (1, -1))]
    print("compound groups (median per call):")
    for label, features in [
        ("two cube faces", [Plane((1, 0, 0), (1, 0, 0)), Plane((0, 1, 0), (0, 1, 0))]),
        ("shaft + shoulder", [pin, head]),
        ("four pins on a square", pins),
        ("four pins + shoulder", [*pins, top]),
        (
            "gear hub (bore, two faces)",
            [Hole((0, 0, 0), Z, 3, directed=False), Plane((0, 0, 0), MZ), Plane((0, 0, 5), Z)],
        ),
    ]:
        seconds = median_seconds(lambda features=features: compound_group(features), 5, 3)
        print(f"  {label:28s} {seconds * 1e3:10.2f} ms")
    rng = np.random.default_rng(0)
    poses = [se3.random_transform(rng, 5.0) for _ in range(1000)]
    print("residual evaluations (rate):")
    for kind, first, second in [
        ("against", head, top),
        ("fits", pin, Hole((0, 0, 0), MZ, 5, directed=False)),
        ("fits", bolt, nut),
    ]:
        residual = relation_residual(kind, first, second)
        seconds = median_seconds(lambda residual=residual: [residual(x) for x in poses], 5, 1)
        print(f"  {kind + ' ' + second.type_name:28s} {len(poses) / seconds:10.0f} /s")


if __name__ == "__main__":
    main()
