"""PNG pictures (viz/plots.py): the storyboard of a plan and the NDBG map."""

from __future__ import annotations

import numpy as np
import trimesh
from matplotlib.image import imread

from assemblykit.blocking.graphs import blocking_graph
from assemblykit.model.assembly import Assembly, Part
from assemblykit.planning.sequence import Plan, Step
from assemblykit.viz.plots import _count_colors, exploded_view_png, plot_ndbg, storyboard_frames


def row_of_blocks(n: int) -> Assembly:
    """``n`` unit cubes side by side along x."""
    return Assembly(
        [
            Part(f"b{i}", trimesh.creation.box(extents=(1, 1, 1)).apply_translation((i, 0, 0)))
            for i in range(n)
        ]
    )


def test_storyboard_frames_spread_over_the_plan():
    assert storyboard_frames(2) == [0, 1, 2]
    assert storyboard_frames(10, panels=3) == [0, 5, 10]


def test_the_storyboard_of_a_long_plan_draws_arrows_and_no_streak(tmp_path):
    assembly = row_of_blocks(40)
    up = np.array([0.0, 0.0, 1.0])
    steps = tuple(
        Step((f"b{i}",), up, tuple(f"b{j}" for j in range(i + 1, 40)), ()) for i in range(39)
    )
    plan = Plan(tuple(assembly.names), steps, (), None, 1)
    path = exploded_view_png(assembly, plan, tmp_path / "s.png", dpi=40)
    pixels = imread(path)[..., :3]
    assert pixels.shape[1] > pixels.shape[0]  # 2 rows of 3 panels
    black = np.all(pixels < 0.1, axis=-1)  # the arrows (and titles)
    bare = exploded_view_png(
        assembly, Plan(plan.parts, (), (), None, 1), tmp_path / "b.png", dpi=40
    )
    assert black.sum() > np.all(imread(bare)[..., :3] < 0.1, axis=-1).sum()
    # every panel fitted to the assembly: the row spans a good part of a panel
    top_left = ~np.all(pixels[: pixels.shape[0] // 2, : pixels.shape[1] // 3] > 0.97, axis=-1)
    cols = np.flatnonzero(top_left[top_left.shape[0] // 5 :].any(axis=0))
    assert cols.max() - cols.min() > 0.3 * top_left.shape[1]


def test_the_ndbg_colours_span_the_counts_that_occur(tmp_path):
    assert tuple(_count_colors(3)(0)) == (0.9, 0.9, 0.9, 1.0)  # nobody free: grey
    assert _count_colors(3).N == 4
    base = trimesh.creation.box(extents=(2, 2, 1)).apply_translation((0, 0, 0.5))
    lid = trimesh.creation.box(extents=(1, 1, 1)).apply_translation((0, 0, 1.5))
    ndbg = blocking_graph(Assembly([Part("base", base), Part("lid", lid)]))
    path = plot_ndbg(ndbg, tmp_path / "n.png", dpi=40)
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
