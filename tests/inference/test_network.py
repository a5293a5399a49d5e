"""The relational network of body instances (seed 000 §III A-B)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from assemblykit.algebra import se3
from assemblykit.errors import SchemaError
from assemblykit.features.primitives import Hole, Plane, Point, Shaft
from assemblykit.inference.network import WORLD, build_network, instance_key
from assemblykit.model.body import Body
from assemblykit.model.relations import FeatureRef, Relation
from assemblykit.model.task import Action, Situation, Task

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
