"""The parts a model names as falling (:meth:`EquilibriumModel.slack`, solved piece by
piece on the corners of the contact polygons, each piece's residuals kept) must be those
of the slack program written out over every free part and every polygon vertex at once:
every part that program leaves unbalanced by more than ten times the tolerance is named,
and every part named is unbalanced by a tenth of the tolerance at least.

The states are two of the cross vault taken down from the top. In each, one block is
balanced by the converged least-residual balance (to a fraction of the tolerance, 5e-5
of its weight), but an answer within Clarabel's default accuracy (1e-8) of the least
residual leaves it unbalanced by a hundredth of its weight or under the tolerance,
depending on how the program is written (whole or by pieces, every vertex or corners):
the slack program is solved to :data:`~assemblykit.planning.stability.SLACK_ACCURACY`."""

from __future__ import annotations

import pytest

from assemblykit.planning.stability import (
    EquilibriumModel,
    equilibrium_model,
)
from assemblykit.tolerance import Tolerance
from datasets import shared_assembly
from stability_blocks import whole_residuals

TWO_PIECES = """
2 26 27 31 32 56 58 59 60 62 63 65 69 71 74 80 81 84 85 86 87 88 89 90 120 122 124 127 128
177 180
""".split()  # noqa: SIM905
"""31 blocks on block 180, in two pieces (18 and 12 free blocks); block 59 is balanced
(stopped at 1e-8: 7.8e-3 of its weight unbalanced on every vertex at once, 3.1e-5 on
the corners piece by piece)."""

ONE_PIECE = """
5 6 10 11 12 13 17 18 21 23 24 25 26 27 28 29 31 32 33 34 36 39 40 41 42 43 48 49 56 58 59
60 61 62 63 64 65 69 71 74 75 76 77 78 79 80 81 82 84 142 150 177 180 181 182
""".split()  # noqa: SIM905
"""55 blocks on blocks 180, 181 and 182, in one piece; block 25 is balanced (stopped at
1e-8: 5.1e-3 of its weight unbalanced on every vertex, 2.9e-5 on the corners)."""


@pytest.fixture(scope="module")
def vault() -> EquilibriumModel:
    assembly = shared_assembly("compas_assembly/crossvault_assembly.json")
    return equilibrium_model(assembly, friction=0.5, tol=Tolerance.relative(5e-5))


@pytest.mark.parametrize(
    ("state", "pieces", "part"),
    [
        pytest.param(TWO_PIECES, [18, 12], "59", id="two-pieces"),
        pytest.param(ONE_PIECE, [52], "25", id="one-piece"),
    ],
)
def test_the_parts_named_falling_are_the_whole_programs(vault, state, pieces, part):
    present = vault.mask(state)
    fixed = present & vault.mask(vault.fixed)
    assert sorted(int(p.sum()) for p in vault.pieces(present, fixed)) == sorted(pieces)
    found = vault.check(state)
    assert not found.stands
    named = set(found.would_fall)
    residual = whole_residuals(vault, present, fixed)
    unbalanced = {name for name, r in residual.items() if r > 10 * vault.threshold}
    assert unbalanced <= named
    assert all(residual[name] > vault.threshold / 10 for name in named)
    assert part not in named and residual[part] < vault.threshold
