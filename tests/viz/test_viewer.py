"""Tests of the HTML report: the figure, the per-step data of the page's script, the
tables in words, the size of large reports and the CDN option."""

from __future__ import annotations

import base64
import json
import re

import numpy as np
import pytest
import trimesh

from assemblykit.model.assembly import Assembly, Part
from assemblykit.planning.sequence import Interlock, Plan, Step
from assemblykit.viz.viewer import (
    ARROW_FRACTION,
    DIM_COLOR,
    PALETTE,
    TRIAD_COLORS,
    TRIAD_FRACTION,
    ReportTable,
    face_colors,
    figure,
    frame_colors,
    part_colors,
    ray_exit,
    report_html,
    scene,
    triad,
    triad_labels,
    triad_origin,
    view_box,
    write_report,
)

UP = np.array([0.0, 0.0, 1.0])


def two_boxes() -> Assembly:
    """A 2 x 2 x 1 block with a unit cube on top (touching, no overlap)."""
    base = trimesh.creation.box(extents=(2, 2, 1))
    base.apply_translation((0, 0, 0.5))
    lid = trimesh.creation.box(extents=(1, 1, 1))
    lid.apply_translation((0, 0, 1.5))
    return Assembly([Part("base", base), Part("lid<1>", lid)])


def lifted(assembly: Assembly) -> Plan:
    step = Step(("lid<1>",), UP, ("base",), (("base", "lid<1>"),))
    return Plan(tuple(assembly.names), (step,), (), None, 4)


def page_data(page: str) -> dict:
    """The JSON the page's script walks through."""
    return json.loads(re.search(r"const P = (\{.*?\});\n", page).group(1))


def test_one_trace_holds_every_part_one_the_arrow_and_two_the_axes():
    assembly = two_boxes()
    fig = figure(assembly, lifted(assembly))
    assert [t.type for t in fig.data] == ["mesh3d", "mesh3d", "mesh3d", "scatter3d"]
    parts, arrow, axes, names = fig.data
    assert len(parts.i) == 24 and len(parts.x) == 16  # two boxes: 12 triangles, 8 corners
    # each face in its part's colour, the colour of the legend
    legend = part_colors(assembly.names)
    assert list(parts.facecolor) == [legend["base"]] * 12 + [legend["lid<1>"]] * 12
    assert parts.intensity is None
    assert arrow.visible is False and fig.frames == ()
    assert fig.layout.showlegend is False
    assert list(names.text) == ["X", "Y", "Z"] and list(names.textfont.color) == list(TRIAD_COLORS)
    assert set(axes.facecolor) == set(TRIAD_COLORS)


def test_the_step_parts_keep_their_colour_and_every_other_part_turns_one_grey():
    assembly = row_of_blocks(5)
    step = Step(("b1", "b3"), UP, ("b0", "b2", "b4"), ())
    plan = Plan(tuple(assembly.names), (step,), (), None, 1)
    drawn = scene(assembly, plan)
    legend = part_colors(assembly.names)
    assert face_colors(assembly, drawn, 0) == [legend[n] for n in assembly.names for _ in range(12)]
    shown = face_colors(assembly, drawn, 1)
    expected = [legend[n] if n in step.parts else DIM_COLOR for n in assembly.names]
    assert shown == [c for c in expected for _ in range(12)]
    data = page_data(report_html(assembly, plan))
    assert data["colors"] == [legend[n] for n in assembly.names] and data["dim"] == DIM_COLOR
    assert frame_colors(["#ff0000"], [0], 1) == [DIM_COLOR]  # never moved: grey in a step


def row_of_blocks(n: int, gap: float = 0.0) -> Assembly:
    """``n`` unit cubes along y, ``gap`` apart."""
    return Assembly(
        [
            Part(
                f"b{i}",
                trimesh.creation.box(extents=(1, 1, 1)).apply_translation((0, i * (1 + gap), 0)),
            )
            for i in range(n)
        ]
    )


def test_a_ray_leaves_a_closed_mesh_where_it_crosses_it_last():
    box = trimesh.creation.box(extents=(2, 2, 2))
    triangles = np.asarray(box.triangles)
    centre, up = np.zeros(3), np.array([0.0, 0.0, 1.0])
    assert ray_exit(centre, up, triangles) == pytest.approx(1.0)
    diagonal = np.array([1.0, 1.0, 1.0]) / np.sqrt(3)  # through a corner: an edge of six
    assert ray_exit(centre, diagonal, triangles) == pytest.approx(np.sqrt(3))
    assert ray_exit(np.array([5.0, 0.0, 0.0]), up, triangles) is None  # beside it
    assert ray_exit(np.array([0.0, 0.0, 5.0]), up, triangles) is None  # behind the ray
    assert ray_exit(centre, up, np.zeros((0, 3, 3))) is None


def arrow_tail(arrow: trimesh.Trimesh, d: np.ndarray) -> np.ndarray:
    """The centre of the arrow's back end: its vertices furthest back along ``d``."""
    heights = np.asarray(arrow.vertices) @ d
    return np.asarray(arrow.vertices)[heights < heights.min() + 1e-9].mean(axis=0)


def test_the_arrow_starts_on_the_moved_parts_even_when_they_stand_apart():
    # the two outer blocks of a row leave along +x: the centre of their bounding box is
    # in the middle block, which stays; the arrow starts on one of the moved blocks
    assembly = row_of_blocks(3, gap=4.0)
    d = np.array([1.0, 3.011e-05, -6.204e-06])
    d /= np.linalg.norm(d)
    step = Step(("b0", "b2"), d, ("b1",), ())
    plan = Plan(tuple(assembly.names), (step,), (), None, 1)
    drawn = scene(assembly, plan)
    tail = arrow_tail(drawn.arrows[0], d)
    distances = [
        float(
            np.linalg.norm(
                tail
                - trimesh.proximity.closest_point(
                    assembly.parts[n].mesh.copy().apply_translation(drawn.frames.offset(n, 1)),
                    [tail],
                )[0][0]
            )
        )
        for n in step.parts
    ]
    assert min(distances) < 1e-6 * assembly.scale
    # on the face it leaves by, level with the block's centre
    assert tail[0] == pytest.approx(0.5 + drawn.frames.distance(1), abs=1e-6)
    assert abs(tail[2]) < 1e-3
    # a group that holds its centre: the arrow leaves it from there
    lid = scene(two_boxes(), lifted(two_boxes()))
    assert arrow_tail(lid.arrows[0], UP)[:2] == pytest.approx([0, 0], abs=1e-9)


def test_the_axis_triad_stands_beside_the_assembly_inside_the_view():
    assembly = two_boxes()
    mesh, colors = triad(assembly)
    lo, hi = view_box(assembly)
    assert np.all(mesh.bounds[0] >= lo) and np.all(mesh.bounds[1] <= hi)
    labels = triad_labels(assembly)
    assert np.all(labels >= lo) and np.all(labels <= hi)
    origin = triad_origin(assembly)
    assert np.all(origin < assembly.bounds[0])  # below, left of and before the assembly
    # each arrow along its axis, in its colour
    for axis, color in enumerate(TRIAD_COLORS):
        faces = np.asarray(mesh.faces)[np.asarray(colors) == color]
        reach = mesh.vertices[np.unique(faces)] - origin
        assert reach[:, axis].max() == pytest.approx(TRIAD_FRACTION * assembly.scale)


def test_the_camera_box_is_fitted_to_the_assembled_state():
    assembly = two_boxes()  # 2 x 2 x 2 around (0, 0, 1)
    lo, hi = view_box(assembly)
    # 1.5 x the half-extents (1, 1, 1) around the centre
    assert np.allclose(lo, [-1.5, -1.5, -0.5]) and np.allclose(hi, [1.5, 1.5, 2.5])
    scene = figure(assembly, lifted(assembly)).layout.scene
    assert list(scene.zaxis.range) == pytest.approx([-0.5, 2.5])


def test_the_script_moves_the_step_parts_inside_the_view_with_an_arrow():
    assembly = two_boxes()
    page = report_html(assembly, lifted(assembly), title="boxes")
    data = page_data(page)
    assert data["names"] == ["base", "lid<1>"]
    assert data["stepOf"] == [0, 1] and data["directions"] == [[0.0, 0.0, 1.0]]
    vertices = np.frombuffer(base64.b64decode(data["vertices"]), dtype=np.float32)
    assert vertices.reshape(-1, 3)[8:, 2].min() == 1.0  # the lid's corners follow the base's
    # the view ends at z = 2.5: the lid (top at 2) and its arrow (0.12 x the diagonal
    # sqrt(12) = 0.4157) leave 0.0843 of room, less than the smallest move, 3% of the
    # diagonal: 0.1039
    arrow = ARROW_FRACTION * assembly.scale
    assert arrow == pytest.approx(0.41569, abs=1e-5)
    assert data["travel"][1] == pytest.approx(0.103923, abs=1e-6)
    tip = np.asarray(data["arrows"][0])  # rows x, y, z of the arrow's vertices
    assert tip[2].min() == pytest.approx(2.103923, abs=1e-4)
    assert tip[2].max() == pytest.approx(2.103923 + 0.41569, abs=1e-4)
    assert (
        data["captions"][1] == "Step 1 of 1: lid<1> moves along +Z (translation) away from 1 part."
    )
    assert data["labels"] == ["assembled", "step 1 of 1"]


def test_the_page_says_it_in_words_and_folds_long_lists(tmp_path):
    names = [f"b{i}" for i in range(12)]
    blocks = [
        trimesh.creation.box(extents=(1, 1, 1)).apply_translation((i, 0, 0)) for i in range(12)
    ]
    assembly = Assembly([Part(n, m) for n, m in zip(names, blocks, strict=True)])
    step = Step(tuple(names[:1]), np.array([0.0, -1.0, 1e-17]), tuple(names[1:]), ())
    plan = Plan(tuple(names), (step,), (), None, 3)
    page = report_html(assembly, plan)
    assert "<td>-Y</td>" in page  # the direction as an axis, the tiny component dropped
    assert "<details><summary>11 parts</summary>b1, b2," in page  # away from: a count
    assert "<script src=" not in page and len(page) > 3_000_000  # plotly.js embedded
    assert page.count('class="swatch"') == 12  # the part list, grouped by step
    assert "<summary>12 parts, by step</summary>" in page
    small = write_report(assembly, plan, tmp_path / "r.html", plotlyjs="cdn")
    text = small.read_text(encoding="utf-8")
    assert 'src="https://cdn.plot.ly/plotly-' in text and small.stat().st_size < 200_000


def test_extra_tables_and_interlocks_are_tables_without_paths():
    assembly = two_boxes()
    lock = Interlock(("base", "lid<1>"), translation_locked=True, rigid_may_free=False)
    plan = Plan(tuple(assembly.names), (), (lock,), None, 1)
    motion = ReportTable("Motion of each part", ("part", "motion"), (("lid<1>", "fixed"),))
    page = report_html(assembly, plan, extra=(motion,))
    assert "infeasible: interlocked parts base, lid&lt;1&gt;" in page
    assert "<td>base, lid&lt;1&gt;</td><td>yes</td><td>no</td>" in page
    assert "<h2>Motion of each part</h2>" in page
    assert "<tr><td>lid&lt;1&gt;</td><td>fixed</td></tr>" in page
    assert "<pre>" not in page


def test_a_report_of_hundreds_of_parts_carries_the_geometry_once():
    blocks = [
        Part(
            f"p{i}", trimesh.creation.box(extents=(1, 1, 1)).apply_translation((i % 20, i // 20, 0))
        )
        for i in range(400)
    ]
    assembly = Assembly(blocks)
    steps = tuple(
        Step((f"p{i}",), UP, tuple(f"p{j}" for j in range(i + 1, 400)), ()) for i in range(399)
    )
    page = report_html(assembly, Plan(tuple(assembly.names), steps, (), None, 1))
    plotly_js = 4_000_000
    assert len(page) - plotly_js < 3_000_000  # not 400 steps x 400 traces
    assert len(set(page_data(page)["arrows"][0][0])) > 1
    assert set(page_data(page)["colors"]) == set(PALETTE)  # the palette, repeated
