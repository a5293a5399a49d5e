"""The relational network of body instances (Corner et al. 1983 §III A-B)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from assemblykit.algebra import se3
from assemblykit.errors import SchemaError
from assemblykit.features.primitives import Hole, Plane, Point, Shaft
from assemblykit.inference.network import WORLD, build_network, instance_key, meet_loci
from assemblykit.model.body import Body
from assemblykit.model.relations import FeatureRef, Relation
from assemblykit.model.task import Action, Situation, Task
from assemblykit.tolerance import Tolerance

Z = (0.0, 0.0, 1.0)


def rel(kind: str, first: str, second: str, **options) -> Relation:
    return Relation(kind, (FeatureRef.parse(first), FeatureRef.parse(second)), options)


def bodies() -> dict[str, Body]:
    table = Body("table", {"top": Plane((0, 0, 0), Z), "bore": Hole((5, 0, 0), Z, 1.0)}, True)
    block = Body(
        "block",
        {"bottom": Plane((0, 0, 0), (0, 0, -1)), "mark": Point((1, 0, 0))},
    )
    peg = Body("peg", {"shaft": Shaft((0, 0, 0), (1, 0, 0), 1.0), "end": Plane((0, 0, 0), Z)})
    return {"table": table, "block": block, "peg": peg}


def task(*situations: Situation) -> Task:
    return Task("mm", bodies(), situations)


S1 = Situation(
    "s1",
    (
        rel("against", "block.bottom", "table.top"),
        rel("fits", "peg.shaft", "table.bore"),
        rel("point_on_plane", "block.mark", "peg.end"),
    ),
)


def test_instances_links_and_constraints_of_one_situation():
    net = build_network(task(S1))
    assert net.instances == (("block", "s1"), ("peg", "s1"))
    assert net.fixed == frozenset({"table"})
    assert net.node("table", "s1") == WORLD
    assert [(link.source, link.target) for link in net.links] == [
        (WORLD, ("block", "s1")),
        (WORLD, ("peg", "s1")),
    ]
    assert net.links[0].labels == ("against block.bottom table.top @s1",)
    assert (net.links[0].value.dof, str(net.links[0].value.kind)) == (3, "planar")
    (constraint,) = net.constraints
    assert constraint.nodes == (("peg", "s1"), ("block", "s1"))
    assert constraint.labels == ("point_on_plane block.mark peg.end @s1",)
    # the mark (1,0,0) of the block is 2 above the peg's end plane when the peg is 2 lower
    assert constraint.residual([shift(0, 0, -2), np.eye(4)]) == pytest.approx([2.0])
    assert instance_key(("block", "s1")) == "block@s1"
    assert sorted(net.graph().edges()) == sorted([(WORLD, ("block", "s1")), (WORLD, ("peg", "s1"))])


def shift(x: float, y: float, z: float) -> np.ndarray:
    return se3.translation((x, y, z))


@pytest.mark.parametrize(
    ("action", "dof", "rep"),
    [
        (Action("move", "peg", along=FeatureRef("peg", "shaft"), by=3.0), 0, shift(3, 0, 0)),
        (Action("move", "peg", along=FeatureRef("peg", "shaft")), 1, np.eye(4)),
        (
            Action("turn", "peg", about=FeatureRef("peg", "shaft"), by=math.pi / 2),
            0,
            se3.rot_x(math.pi / 2),
        ),
        (Action("turn", "peg", about=FeatureRef("peg", "shaft")), 1, np.eye(4)),
    ],
)
def test_action_links(action, dof, rep):
    net = build_network(task(S1, Situation("s2", (), (action,))))
    (link,) = [k for k in net.links if k.source == ("peg", "s1")]
    assert link.target == ("peg", "s2")
    assert link.value.dof == dof
    assert np.allclose(link.value.rep, rep, atol=1e-12)
    if dof == 1:
        assert str(link.value.kind) == ("prismatic" if action.kind == "move" else "revolute")
        assert np.allclose(np.abs(link.value.group.axis), (1, 0, 0))
    residual = net.link_constraint(link).residual
    assert np.allclose(residual([np.eye(4), rep]), 0)
    assert not np.allclose(residual([np.eye(4), shift(0, 1, 0)]), 0)


def test_free_move_has_no_link_and_stationary_bodies_keep_their_pose():
    net = build_network(task(S1, Situation("s2", (), (Action("move", "peg"),))))
    transitions = [k for k in net.links if k.source[1] == "s1" and k.target[1] == "s2"]
    assert [(k.source, k.target) for k in transitions] == [(("block", "s1"), ("block", "s2"))]
    (stay,) = transitions
    assert stay.labels == ("stationary block @s2",)
    assert stay.value.is_point and np.allclose(stay.value.rep, np.eye(4))
    assert net.instances == (("block", "s1"), ("peg", "s1"), ("block", "s2"), ("peg", "s2"))


def test_coupled_relations_find_their_carrier():
    gripper = {
        "palm": Body("palm", {"rail": Plane((0, 0, 0), Z)}, True),
        "a": Body(
            "a", {"foot": Plane((0, 0, 0), (0, 0, -1)), "face": Plane((-1, 0, 0), (1, 0, 0))}
        ),
        "b": Body(
            "b", {"foot": Plane((0, 0, 0), (0, 0, -1)), "face": Plane((1, 0, 0), (-1, 0, 0))}
        ),
    }
    relations = (
        rel("against", "a.foot", "palm.rail"),
        rel("against", "b.foot", "palm.rail"),
        rel("mirror", "a.face", "b.face"),
    )
    net = build_network(Task("mm", gripper, (Situation("s1", relations),)))
    (mirror,) = net.constraints
    assert mirror.nodes == (("a", "s1"), ("b", "s1"), WORLD)
    # a moves +0.25 along x, b moves -0.25: equal and opposite
    assert mirror.residual([shift(0.25, 0, 0), shift(-0.25, 0, 0), np.eye(4)]) == pytest.approx(
        [0.0]
    )
    assert mirror.residual([shift(0.25, 0, 0), np.eye(4), np.eye(4)]) == pytest.approx([0.25])
    lonely = Task("mm", gripper, (Situation("s1", (relations[0], relations[2])),))
    with pytest.raises(SchemaError, match="no body is related to both"):
        build_network(lonely)


def test_loci_meet_in_a_line_a_point_or_miss_by_their_gap():
    tol = Tolerance()
    x_plane = (np.array([1.0, 0, 0]), np.array([1.0, 7, 7]))
    y_plane = (np.array([0, 1.0, 0]), np.array([3.0, 2, 3]))
    origin, rows = meet_loci(np.zeros(3), np.zeros((0, 3)), [x_plane, y_plane], tol)
    # x = 1 and y = 2 meet in the vertical line through (1, 2, 0)
    np.testing.assert_allclose(origin, [1, 2, 0], atol=1e-15)
    np.testing.assert_allclose(np.cross(rows[0], rows[1]), [0, 0, 1], atol=1e-15)
    tilted = (np.array([0, 0.6, 0.8]), np.array([0, 0, 5.0]))
    point, rows = meet_loci(origin, rows, [tilted], tol)
    # 0.6·2 + 0.8·z = 4 on that line: z = 3.5
    np.testing.assert_allclose(point, [1, 2, 3.5], atol=1e-15)
    assert len(rows) == 3
    apart = (np.array([-1.0, 0, 0]), np.array([4.0, 0, 0]))
    assert meet_loci(origin, rows[:2], [apart], tol) == pytest.approx(3.0, abs=1e-15)


def test_point_loci_of_one_point_are_folded_into_one_spherical_link():
    box = Body(
        "box", {"x": Plane((1, 0, 0), (1, 0, 0)), "y": Plane((0, 2, 0), (0, 1, 0))}, fixed=True
    )
    tip = Body("v", {"tip": Point((0, 0, 1)), "rod": Shaft((0, 0, 0), (0, 0, 1), 1.0)})
    s1 = Situation(
        "s1",
        (
            rel("point_on_plane", "v.tip", "box.x"),
            rel("point_on_plane", "v.tip", "box.y"),
            rel("distance", "v.tip", "box.x", distance=0.0),
            rel("point_on_line", "v.tip", "v.rod"),
        ),
    )
    s2 = Situation("s2", (rel("point_on_plane", "v.tip", "box.x"),), (Action("move", "v"),))
    net = build_network(Task("mm", {"box": box, "v": tip}, (s1, s2)))
    # the tip's own rod is no locus of another body: it stays a plain constraint; the
    # three relations of the tip in s1 meet in the line x = 1, y = 2; s2 keeps the plane
    kinds = [(c.labels[0].split()[0], len(c.labels)) for c in net.constraints]
    assert kinds == [("point_on_line", 1), ("point_on_plane", 3), ("point_on_plane", 1)]
    assert [c.geometry.rank for c in net.constraints[1:]] == [2, 1]
    np.testing.assert_allclose(net.constraints[1].geometry.origin, [1, 2, 0], atol=1e-15)
    assert not net.links  # a free move links nothing
    box_z = Body("box", {**box.features, "z": Plane((0, 0, 3), (0, 0, 1))}, fixed=True)
    corner = Situation("s1", (*s1.relations[:2], rel("point_on_plane", "v.tip", "box.z")))
    (link,) = build_network(Task("mm", {"box": box_z, "v": tip}, (corner,))).links
    # x = 1, y = 2, z = 3: the tip (0, 0, 1) turns about (1, 2, 3)
    assert (link.source, link.target, link.value.dof, str(link.value.kind)) == (
        WORLD,
        ("v", "s1"),
        3,
        "spherical",
    )
    np.testing.assert_allclose(link.value.rep, se3.translation((1, 2, 2)), atol=1e-15)
    assert len(link.labels) == 3
