"""Tests of the HTML report: figure structure, exploded frames, tables, offline page."""

from __future__ import annotations

import numpy as np
import trimesh

from assemblykit.model.assembly import Assembly, Part
from assemblykit.planning.sequence import Interlock, Plan, Step
from assemblykit.viz.viewer import EXPLODE_FRACTION, figure, report_html, write_report

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


def test_figure_has_a_mesh_per_part_and_a_frame_per_step():
    assembly = two_boxes()
    fig = figure(assembly, lifted(assembly))
    assert [t.type for t in fig.data] == ["mesh3d", "mesh3d"]
    assert [t.name for t in fig.data] == ["base", "lid<1>"]
    assert len(fig.data[0].i) == 12  # a box has 12 triangles
    assert [f.name for f in fig.frames] == ["0", "1"]
    slider = fig.layout.sliders[0]
    assert [s.label for s in slider.steps] == ["assembled", "1"]
    assert list(slider.steps[1].args[0]) == ["1"]
    assert slider.steps[1].method == "animate"
    # step 1 lifts the lid by the explode distance; the base stays
    shift = EXPLODE_FRACTION * assembly.scale
    lid_z = np.asarray(fig.frames[1].data[1].z)
    assert np.allclose(lid_z.min(), 1.0 + shift, atol=1e-5)
    assert np.allclose(np.asarray(fig.frames[1].data[0].z).max(), 1.0)
    # the camera box holds the lifted lid
    assert fig.layout.scene.zaxis.range[1] >= 2.0 + shift - 1e-5


def test_report_is_self_contained_and_lists_steps_and_blocking(tmp_path):
    assembly = two_boxes()
    page = report_html(assembly, lifted(assembly), title="boxes")
    assert page.startswith("<!DOCTYPE html>")
    assert "<script src=" not in page  # plotly.js is embedded, no CDN
    assert len(page) > 3_000_000
    assert "<td>lid&lt;1&gt;</td>" in page  # names are escaped
    assert "<td>(0.000, 0.000, 1.000)</td>" in page
    # the lid held the base in place along +z: listed as held in place
    assert "<td>base</td></tr>" in page
    path = write_report(assembly, lifted(assembly), tmp_path / "sub" / "r.html")
    assert path.read_text(encoding="utf-8") == report_html(assembly, lifted(assembly))


def test_infeasible_report_lists_the_interlocked_parts():
    assembly = two_boxes()
    lock = Interlock(("base", "lid<1>"), translation_locked=True, rigid_may_free=False)
    plan = Plan(tuple(assembly.names), (), (lock,), None, 1)
    page = report_html(assembly, plan, extra={"Motion": {"lid": "fixed"}})
    assert "infeasible: interlocked parts base, lid&lt;1&gt;" in page
    assert "<h2>Interlocked</h2>" in page
    assert "<td>base, lid&lt;1&gt;</td><td>yes</td><td>no</td>" in page
    assert "&quot;lid&quot;: &quot;fixed&quot;" in page
