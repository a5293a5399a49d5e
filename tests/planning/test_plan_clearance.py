"""Every step of every plan, feasible or not, clear of every part still where it was:
the physical replay of :mod:`plan_checks` on hand-made steps, on a cabinet whose drawer
joints are modelled overlapping, and on the bundled plans."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import trimesh

from assemblykit.blocking.directions import DirectionTable
from assemblykit.blocking.graphs import blocking_graph
from assemblykit.blocking.ndbg import NonDirectionalBlockingGraph
from assemblykit.geometry.interference import solid
from assemblykit.model.assembly import Assembly, Part
from assemblykit.planning.planner import plan
from assemblykit.planning.sequence import Search, Step
from datasets import shared_assembly
from plan_checks import Sweep, assert_steps_clear, step_clashes
from stability_blocks import box

DEMO = Path(__file__).resolve().parents[2] / "src/assemblykit/examples/gearbox_demo/gearbox.yaml"
X, Y, Z = np.eye(3)


def block(low: tuple[float, ...], high: tuple[float, ...]) -> trimesh.Trimesh:
    """The axis-aligned box between two corners."""
    lo, hi = np.asarray(low, dtype=float), np.asarray(high, dtype=float)
    return box(tuple(hi - lo), tuple(lo))


def cut(mesh: trimesh.Trimesh, away: trimesh.Trimesh) -> trimesh.Trimesh:
    return trimesh.boolean.difference([mesh, away], engine="manifold")


def step(parts: tuple[str, ...], direction: np.ndarray, rest: tuple[str, ...] = ()) -> Step:
    return Step(parts=parts, direction=np.asarray(direction, dtype=float), rest=rest, blocking=())


def peg_in_wall(head: bool = False) -> Assembly:
    """A 4 x 4 x 1 wall with a 1 x 1 hole along z and a peg filling it, 3 long (with a
    2 x 2 head on top when ``head``: not convex)."""
    wall = cut(block((0, 0, 0), (4, 4, 1)), block((1.5, 1.5, -1), (2.5, 2.5, 2)))
    peg = block((1.5, 1.5, -1), (2.5, 2.5, 2))
    if head:
        peg = trimesh.boolean.union([peg, block((1, 1, 2), (3, 3, 2.5))], engine="manifold")
    return Assembly([Part("wall", wall), Part("peg", peg)])


# ---------------------------------------------------------------- the checker itself


def test_the_sweep_of_a_box_and_of_a_peg_with_a_head_has_their_exact_volume():
    cube = block((0, 0, 0), (1, 1, 1))
    everything = solid(block((-10, -10, -10), (10, 10, 10)))
    assert Sweep(cube, 2 * X).shared(everything) == pytest.approx(3.0)
    # along a diagonal: 1 + the square's width across it (sqrt 2) times the length
    assert Sweep(cube, np.array([1.0, 1.0, 0.0])).shared(everything) == pytest.approx(3.0)
    peg = peg_in_wall(head=True)["peg"].mesh  # shank 1 x 1 x 3, head 2 x 2 x 0.5
    assert not peg.is_convex
    # sideways by 1: the head sweeps 3 x 2 x 0.5, the shank under it 2 x 1 x 3
    assert Sweep(peg, X).shared(everything) == pytest.approx(3.0 + 6.0)


@pytest.mark.parametrize("head", [False, True])
def test_a_peg_pulled_out_of_its_hole_passes_and_one_pushed_through_the_wall_fails(head):
    assembly = peg_in_wall(head)
    assert_steps_clear(assembly, [step(("peg",), Z, ("wall",))])
    # the step says nothing moves it past: the wall is there all the same
    (clash,) = step_clashes(assembly, [step(("peg",), X)])
    assert (clash.step, clash.moved, clash.obstacle) == (1, "peg", "wall")
    # the wall's part of the shank's sweep: 1.5 thick, 1 x 1 across
    assert clash.volume == pytest.approx(1.5)
    with pytest.raises(AssertionError, match="step 1: peg sweeps"):
        assert_steps_clear(assembly, [step(("peg",), -Y, ("wall",))])
    # down, the head drags through the wall's top: only without a head
    assert bool(step_clashes(assembly, [step(("peg",), -Z)])) == head


def test_parts_modelled_interfering_keep_their_overlap_and_no_more():
    # two boards overlapping 0.5 deep: pulled apart, or slid along the joint out of the
    # overlap, they pass; the side pushed on into the front does not
    assembly = Assembly(
        [
            Part("front", block((0, 0, 0), (10, 1, 5))),
            Part("side", block((0, 0.5, 0), (1, 10, 5))),
        ]
    )
    assert_steps_clear(assembly, [step(("front",), -Y)])
    assert_steps_clear(assembly, [step(("side",), Y)])
    assert_steps_clear(assembly, [step(("front",), Z)])
    (clash,) = step_clashes(assembly, [step(("side",), -Y)])
    assert clash.volume == pytest.approx(5.0) and clash.allowed == pytest.approx(2.5, rel=1e-3)


def test_a_stack_lifted_top_first_passes_and_parts_moved_together_stay_together():
    stack = Assembly([Part(n, block((0, 0, z), (1, 1, z + 1))) for z, n in enumerate("abc")])
    # c then b along +z: b stops short of c, which went further
    assert_steps_clear(stack, [step(("c",), Z), step(("b",), Z)])
    # b and c leave together; then b leaves c sideways (fine) or downwards into a (not:
    # a stayed where it was, b and c are far away) or upwards into c (not)
    assert_steps_clear(stack, [step(("b", "c"), Z), step(("b",), X), step(("b",), -Z)])
    (clash,) = step_clashes(stack, [step(("b", "c"), Z), step(("b",), Z)])
    assert (clash.step, clash.obstacle) == (2, "c")
    # nothing moved: b lifted into c, which is where it was
    assert [c.obstacle for c in step_clashes(stack, [step(("b",), Z)])] == ["c"]


# ---------------------------------------------------------------- the search


def table(names: str, arcs_per_direction: dict[tuple[float, ...], str]) -> DirectionTable:
    """A table from arcs written ``"ab bc"`` (a blocked by b, b blocked by c)."""
    arcs = [
        [(names.index(arc[0]), names.index(arc[1])) for arc in text.split()]
        for text in arcs_per_direction.values()
    ]
    return DirectionTable.from_arcs(tuple(names), list(arcs_per_direction), arcs)


def test_sets_that_leave_at_one_step_are_taken_apart_together():
    # p and q hold each other, r and s too, x (the base) holds all but upwards; along
    # +z both pairs leave x at once. Along +x, p leaves q but r is in its way: p goes
    # only once {p, q} has left {r, s}, which stays stuck
    tab = table(
        "pqrsx",
        {
            (0.0, 0.0, 1.0): "pq qp rs sr xp",
            (1.0, 0.0, 0.0): "px qx rx sx pr qp rs sr",
            (-1.0, 0.0, 0.0): "px qx rx sx pq qp rs sr",
            (0.0, 0.0, -1.0): "px qx rx sx pq qp rs sr",
        },
    )
    search = Search(tab, tab, (1.0, 2.0, 3.0, 1.0, 9.0), lambda *_: None, [], [])
    search.disassemble(0b11111)
    moves = [(s.parts, tuple(s.direction), s.rest) for s in search.steps]
    assert moves == [
        (("p", "q", "r", "s"), (0.0, 0.0, 1.0), ("x",)),
        (("p", "q"), (0.0, 0.0, 1.0), ("r", "s")),
        (("p",), (1.0, 0.0, 0.0), ("q",)),
    ]
    assert search.locked == [0b01100]


# ---------------------------------------------------------------- a cabinet with a drawer


def cabinet(joint: float = 0.5) -> Assembly:
    """A bench organiser (mm): base, top, two walls and a back; a drawer of a front,
    two sides and a bottom that slides out along -y; a post behind the drawer; and on
    each side a post beside the drawer whose tenon slides along +x (-x on the right)
    out of the slot of a bracket above it. The drawer's front and sides, and the top
    with the walls and the back, overlap ``joint`` at their joints (0: they touch)."""
    shank = block((20, 110, 20), (40, 130, 190))
    post = trimesh.boolean.union([shank, block((25, 115, 190), (35, 125, 200))], engine="manifold")
    bracket = cut(block((0, 100, 190), (60, 140, 230)), block((25, 115, 189), (61, 125, 200)))
    mirror = np.diag([-1.0, 1.0, 1.0, 1.0])
    mirror[0, 3] = 400.0
    parts = {
        "base": block((-20, 0, 0), (420, 300, 20)),
        "top": block((-20, 0, 230), (420, 300, 240)),
        "wall_l": block((-20, 0, 20), (0, 300, 230 + joint)),
        "wall_r": block((400, 0, 20), (420, 300, 230 + joint)),
        "back": block((0, 280, 20), (400, 300, 230 + joint)),
        "front": block((40, 0, 20), (360, 15, 185)),
        "side_l": block((40, 15 - joint, 20), (55, 270, 185)),
        "side_r": block((345, 15 - joint, 20), (360, 270, 185)),
        "bottom": block((55, 15, 20), (345, 270, 30)),
        "post_c": block((190, 272, 20), (210, 280, 230)),
        "post_l": post,
        "bracket_l": bracket,
        "post_r": post.copy().apply_transform(mirror),
        "bracket_r": bracket.copy().apply_transform(mirror),
    }
    return Assembly([Part(name, mesh) for name, mesh in parts.items()])


DRAWER = ("front", "side_l", "side_r")


def test_the_posts_beside_a_stuck_drawer_leave_clear_of_it():
    assembly = cabinet()
    result = plan(assembly)
    assert not result.feasible
    assert_steps_clear(assembly, result)
    # the drawer leaves as a unit, along its slide (with the brackets and posts beside
    # it, which nothing holds there either)
    (out,) = [s for s in result.steps if set(DRAWER) <= set(s.parts)]
    assert np.allclose(out.direction, -Y)
    # the posts are then taken off it with the drawer in the way: it is in their rest
    for s in result.steps:
        if {"post_l", "post_r"} & set(s.parts) and s is not out:
            assert set(DRAWER) <= set(s.rest), s
    # the post behind the drawer and the bottom come out after it, the same way
    order = [s.parts for s in result.steps]
    assert order.index(("bottom",)) > order.index(out.parts)
    assert order.index(("post_c",)) > order.index(("bottom",))
    # why the drawer cannot be taken apart: its front and sides share volumes
    (lock,) = [lock for lock in result.interlocked if "front" in lock.parts]
    assert {*lock.parts, *lock.held} == set(DRAWER)
    assert {(a, b) for a, b, _ in lock.interfering} == {("front", "side_l"), ("front", "side_r")}
    assert [v for _, _, v in lock.interfering] == pytest.approx([15 * 0.5 * 165] * 2)
    assert lock.reason.startswith("interfering (front / side_l share 1.24e+03")
    # no number of hands separates parts that share a volume
    assert result.hands is not None and result.hands.needed is None
    # the top, walls and back overlap too: stuck, after leaving the base as a unit
    assert set(result.stuck) == {*DRAWER, "top", "wall_l", "wall_r", "back"}
    assert ("top", "wall_l", "wall_r", "back") in order


def test_the_extended_ndbg_of_boards_among_slotted_brackets_has_their_cones():
    # the drawer's boards are convex, the brackets not: the boards' cones alone are built
    assembly = cabinet()
    ndbg = blocking_graph(assembly, "extended", parts=DRAWER)
    assert isinstance(ndbg, NonDirectionalBlockingGraph)
    # the overlapping joints block every direction
    assert ndbg.removable() == []
    assert blocking_graph(cabinet(joint=0.0), "extended", parts=DRAWER).removable()


def test_driving_the_posts_through_the_drawer_is_caught():
    # the plan that took each set moved at the first step apart on its own: the posts
    # leave their brackets through the drawer's sides, which left with them
    assembly = cabinet()
    steps = [
        step((*DRAWER, "post_l", "bracket_l", "post_r", "bracket_r"), -Y),
        step(("post_r",), -X, ("bracket_r",)),
        step(("post_l",), X, ("bracket_l",)),
    ]
    clashes = step_clashes(assembly, steps)
    hit = {(c.step, c.moved, c.obstacle) for c in clashes}
    assert {(2, "post_r", "side_r"), (3, "post_l", "side_l")} <= hit
    assert all(c.step > 1 for c in clashes)


def test_the_cabinet_with_touching_joints_comes_apart_clear():
    assembly = cabinet(joint=0.0)
    result = plan(assembly)
    assert result.feasible
    assert_steps_clear(assembly, result)


# ---------------------------------------------------------------- bundled plans


def test_the_gearbox_plan_is_clear():
    assembly = shared_assembly(DEMO)
    result = plan(assembly, max_and_or_parts=0)
    assert result.feasible
    assert_steps_clear(assembly, result)


def test_the_arch_plan_is_clear():
    assembly = shared_assembly("compas_assembly/arch_assembly.json")
    assert_steps_clear(assembly, plan(assembly, max_and_or_parts=0))


@pytest.mark.slow
def test_the_asap_beam_plan_is_clear():
    assembly = shared_assembly("asap_beam_assembly")
    result = plan(assembly, max_and_or_parts=0)
    assert result.feasible
    assert_steps_clear(assembly, result)
