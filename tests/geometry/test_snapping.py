"""Snapping the directions of contacts: which patches' normals become one direction."""

from __future__ import annotations

import numpy as np
import pytest

from assemblykit.geometry.snapping import snap_classes
from assemblykit.tolerance import Tolerance


def _square(half: float) -> np.ndarray:
    return np.array([[-half, -half, 0], [half, -half, 0], [half, half, 0], [-half, half, 0]])


@pytest.mark.parametrize(("scatter", "snapped_to"), [(1e-5, 0), (0.0, 1)])
def test_a_normal_snaps_when_turning_it_moves_within_the_scatter(scatter, snapped_to):
    # two unit squares, normals 2e-5 rad apart (about x): turning the second onto the
    # first moves its edge at y = +-0.5 by 1e-5, within twice their scatter (4e-5) and
    # the tolerance (1e-4); faces without scatter are exact and keep their normals
    tilt = 2e-5
    directions = np.array([[0, 0, 1.0], [0, -np.sin(tilt), np.cos(tilt)]])
    tol = Tolerance(scale=1.0, rel_length=1e-4)
    leader, sign = snap_classes(
        directions, [_square(0.5), _square(0.5)], np.array([scatter, scatter]), tol
    )
    assert leader.tolist() == [0, snapped_to] and sign.tolist() == [1.0, 1.0]


def test_a_normal_turned_further_than_the_tolerance_leads_its_own_class():
    # 4e-4 rad over a half-width of 0.5 moves the edge by 2e-4 > 1e-4
    tilt = 4e-4
    directions = np.array([[0, 0, 1.0], [0, -np.sin(tilt), -np.cos(tilt)]])
    tol = Tolerance(scale=1.0, rel_length=1e-4)
    leader, _ = snap_classes(directions, [_square(0.5)] * 2, np.array([1e-4, 1e-4]), tol)
    assert leader.tolist() == [0, 1]


def _snap_one_leader_at_a_time(directions, spreads, scatter, tol):
    """snap_classes as its docstring states it, each patch compared with every leader."""
    width = [np.linalg.svd(p, compute_uv=False)[1] / np.sqrt(len(p)) for p in spreads]
    leader, sign, leaders = list(range(len(directions))), [1.0] * len(directions), []
    for i in np.argsort(-np.array(width), kind="stable").tolist():
        best = None
        for k in leaders:
            facing = -1.0 if directions[k] @ directions[i] < 0 else 1.0
            turn = np.cross(directions[i], facing * directions[k])
            sine = np.linalg.norm(turn)
            if sine == 0:
                continue
            lever = np.linalg.norm(np.cross(turn / sine, spreads[i]), axis=1).max()
            if sine * lever <= min(2 * (scatter[i] + scatter[k]), tol.length) and (
                best is None or sine < best[0]
            ):
                best = (sine, k, facing)
        if best is None:
            leaders.append(i)
        else:
            leader[i], sign[i] = best[1], best[2]
    return leader, sign


def test_snapping_compares_each_patch_with_every_leader_as_stated():
    """Patches on the three axes, many with exactly one direction (exact faces, which
    the search keeps apart as leaders of one line) and some tilted by 1e-7 with scatter:
    the classes equal those of comparing each patch with every leader one by one."""
    rng = np.random.default_rng(7)
    tol = Tolerance(scale=1.0, rel_length=1e-4)
    joined = 0
    for _ in range(25):
        n = 40
        axes = np.vstack([np.eye(3), -np.eye(3)])[rng.integers(0, 6, n)]
        directions = axes + rng.choice([0.0, 1e-7], n)[:, None] * rng.normal(size=(n, 3))
        directions /= np.linalg.norm(directions, axis=1, keepdims=True)
        spreads = [rng.normal(size=(4, 3)) for _ in range(n)]
        scatter = rng.choice([0.0, 1e-6, 1e-5], n)
        leader, sign = snap_classes(directions, spreads, scatter, tol)
        expected = _snap_one_leader_at_a_time(directions, spreads, scatter, tol)
        assert (leader.tolist(), sign.tolist()) == expected
        joined += int((leader != np.arange(n)).sum())
    assert joined > 400
