"""The picture of a solved task (viz/task_view.py): a panel per situation, every feature
at its body's solved pose, and the freedom glyphs placed by the solution's invariants."""

from __future__ import annotations

from collections import Counter
from pathlib import Path

import numpy as np
import pytest
from matplotlib.image import imread

import assemblykit
from assemblykit.algebra import se3
from assemblykit.inference import solve_task
from assemblykit.io.tasks import load_task
from assemblykit.viz.task_view import (
    LEGEND_HEIGHT,
    PANEL_SIZE,
    feature_gid,
    freedom_gid,
    task_figure,
    write_task_png,
)

TASKS = Path(assemblykit.__file__).parent / "examples" / "tasks"

EVERY_FEATURE = """\
units: mm
bodies:
  world:
    fixed: true
    features:
      home: {type: frame, matrix: [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]}
  kit:
    features:
      mount: {type: frame, matrix: [[0, -1, 0, 10], [1, 0, 0, 0], [0, 0, 1, 2], [0, 0, 0, 1]]}
      face: {type: plane, point: [0, 0, 0], normal: [0, 0, 1]}
      pin: {type: shaft, point: [1, 0, 0], axis: [0, 0, 1], radius: 0.5}
      bore: {type: hole, point: [-1, 0, 0], axis: [0, 0, -1], radius: 0.5}
      knob: {type: ball, point: [0, 2, 0], radius: 0.5}
      cup: {type: socket, point: [0, -2, 0], radius: 0.5}
      tip: {type: cone, point: [2, 2, 0], axis: [0, 0, 1], half_angle: 30 deg}
      ring: {type: torus, point: [-2, 2, 0], axis: [0, 0, 1], major_radius: 1, minor_radius: 0.2}
      screw: {type: thread, point: [2, -2, 0], axis: [0, 0, 1], radius: 0.4, lead: 0.5}
      key: {type: prism, point: [-2, -2, 0], axis: [0, 0, 1], sides: 4, size: 0.5}
      mark: {type: point, point: [3, 0, 0]}
      line: {type: axis, point: [0, 0, 0], axis: [1, 0, 0]}
situations:
  - name: s1
    relations:
      - [fixed, kit.mount, world.home]
"""


def gids(figure) -> Counter[str]:
    """How many artists carry each gid, over every panel."""
    return Counter(
        artist.get_gid()
        for axes in figure.axes
        for artist in axes.get_children()
        if artist.get_gid()
    )


def artist(figure, gid: str):
    (found,) = [a for axes in figure.axes for a in axes.get_children() if a.get_gid() == gid]
    return found


def test_one_3d_panel_per_situation_or_the_last_one():
    task = load_task(TASKS / "peg_in_block.yaml")
    solution = solve_task(task)
    figure = task_figure(task, solution)
    panels = [axes for axes in figure.axes if axes.name == "3d"]
    assert [axes.get_title() for axes in panels] == ["situation s1", "situation s2"]
    (last,) = task_figure(task, solution, panels=1).axes
    assert last.name == "3d" and last.get_title() == "situation s2"


def test_every_feature_type_is_drawn_once_per_instance_at_the_solved_pose(tmp_path: Path):
    path = tmp_path / "every.yaml"
    path.write_text(EVERY_FEATURE)
    task = load_task(path)
    solution = solve_task(task)
    figure = task_figure(task, solution)
    drawn = gids(figure)
    for name, body in task.bodies.items():
        key = f"{name}@s1"
        shown = {g.split(" ")[2] for g in drawn if g.startswith(f"feature {key} ")}
        assert shown == set(body.features), key
    assert len(task.bodies["kit"].features) == 12  # every type of features/primitives.py
    # the datum axis along body x: through the pose's origin along the pose's x axis
    pose = np.asarray(solution["kit@s1"].pose)
    assert np.linalg.norm(pose[:3, 3]) > 1  # a pose that moves the body
    ends = np.array(artist(figure, feature_gid("kit@s1", "line")).get_data_3d()).T
    along = se3.apply_direction(pose, np.array([1.0, 0.0, 0.0]))
    assert np.allclose(ends.mean(axis=0), se3.apply(pose, np.zeros(3)))
    assert np.allclose(np.cross(ends[1] - ends[0], along), 0.0)
    # a fixed instance has no freedom glyph
    assert not [g for g in drawn if g.startswith("freedom ")]


def test_the_revolute_glyph_lies_on_the_axis_the_solution_reports():
    task = load_task(TASKS / "peg_in_block.yaml")
    solution = solve_task(task)
    figure = task_figure(task, solution)
    revolute = solution["peg@s2"]
    point = np.asarray(revolute.invariants["point"])
    direction = np.asarray(revolute.invariants["direction"])
    ends = np.array(artist(figure, freedom_gid("peg@s2", "axis")).get_data_3d()).T
    for end in ends:
        assert np.linalg.norm(np.cross(end - point, direction)) == pytest.approx(0.0, abs=1e-9)
    assert np.linalg.norm(ends[1] - ends[0]) > 0
    drawn = gids(figure)
    # the turn is drawn for both; the slide only where the peg can still slide (s1)
    assert drawn[freedom_gid("peg@s1", "slide")] == 2
    assert freedom_gid("peg@s2", "slide") not in drawn
    assert drawn[freedom_gid("peg@s2", "turn")] == 2  # the arc and its arrowhead
    assert not [g for g in drawn if g.startswith(("freedom block@", "freedom table@"))]


def test_the_glyphs_of_mechanisms_and_of_a_ball_joint():
    task = load_task(TASKS / "point_in_planes.yaml")
    solution = solve_task(task)
    drawn = gids(task_figure(task, solution))
    assert drawn[freedom_gid("three@s1", "ball")] == 3  # three rings about the centre
    assert drawn[freedom_gid("one@s1", "plane")] == 1  # the square in the right-hand plane
    assert drawn[freedom_gid("two@s1", "slide")] == 2  # the double arrow along the line


def test_the_png_has_the_figure_size(tmp_path: Path):
    task = load_task(TASKS / "peg_in_block.yaml")
    written = write_task_png(task, solve_task(task), tmp_path / "task.png", dpi=40)
    assert written.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    width, height = PANEL_SIZE
    assert imread(written).shape[:2] == (
        round(40 * (height + LEGEND_HEIGHT)),
        round(40 * 2 * width),
    )
