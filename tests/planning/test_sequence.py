"""Tests of the disassembly planner (Wilson & Latombe 1992) on hand-made blocking tables and on
real assemblies (the bundled gearbox, the bundled COMPAS and ASAP data)."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
import trimesh

from assemblykit.blocking import tables
from assemblykit.blocking.directions import BlockedRows, DirectionTable, local_table
from assemblykit.blocking.extended import extended_dbg, extended_free
from assemblykit.blocking.graphs import blocking_graph, blocking_terms
from assemblykit.blocking.tables import translation_table
from assemblykit.geometry.overlaps import resolve_overlaps
from assemblykit.io.assembly import load_assembly
from assemblykit.model.assembly import Assembly, Part
from assemblykit.part_sets import mask_of, several
from assemblykit.planning import planner
from assemblykit.planning.planner import plan
from assemblykit.planning.sequence import (
    GROUP_REJECTIONS,
    ExtendedDirections,
    FirstAdmitted,
    Plan,
    Search,
    _choose_removal,
    _free_closures,
    _removal,
    _sinks,
    and_or_graph,
    base_part,
    least_interlocked,
    minimal_interlocked,
    separable,
)
from datasets import dataset, shared_assembly
from plan_checks import assert_steps_clear
from stability_blocks import box

ROOT = Path(__file__).resolve().parents[2]
DEMO = ROOT / "src" / "assemblykit" / "examples" / "gearbox_demo" / "gearbox.yaml"
UP, DOWN = np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, -1.0])


def table(names: str, arcs_per_direction: dict[tuple[float, ...], str]) -> DirectionTable:
    """A table from arcs written ``"ab bc"`` (a blocked by b, b blocked by c)."""
    arcs = [
        [(names.index(arc[0]), names.index(arc[1])) for arc in text.split()]
        for text in arcs_per_direction.values()
    ]
    return DirectionTable.from_arcs(tuple(names), list(arcs_per_direction), arcs)


# a stack: a at the bottom, b on a, c on b; only vertical motions considered
STACK = table("abc", {(0.0, 0.0, 1.0): "ab bc", (0.0, 0.0, -1.0): "ba cb"})
# two parts that block each other both ways
LOCKED = table("pq", {(0.0, 0.0, 1.0): "pq qp", (1.0, 0.0, 0.0): "pq qp"})


def run(
    tab: DirectionTable, volumes: tuple[float, ...], extended: DirectionTable | None = None
) -> Search:
    """The greedy search with ``tab`` as Γ_t and ``extended`` (default: the same) as Γ_e."""
    search = Search(tab, extended or tab, volumes, lambda *_: None, [], [])
    search.disassemble((1 << len(tab.names)) - 1)
    return search


def test_stack_is_taken_apart_from_the_top_keeping_the_direction():
    search = run(STACK, (1.0, 1.0, 1.0))
    # c and a are both free; +z wins the tie, then b stays on +z (no direction change)
    assert [s.parts for s in search.steps] == [("c",), ("b",)]
    assert [tuple(s.direction) for s in search.steps] == [(0, 0, 1), (0, 0, 1)]
    assert search.steps[0].rest == ("a", "b")
    # the moved c held b in place
    assert search.steps[0].blocking == (("b", "c"),)
    assert search.locked == []


def test_and_or_graph_of_the_stack_has_two_plans():
    graph = and_or_graph(STACK)
    # {c | ab} then {b | a}, or {a | bc} then {c | b}; b alone is never free
    assert graph.plans == 2
    assert graph.partitions == 4
    assert graph.subassemblies == 6
    assert graph.to_dict() == {"subassemblies": 6, "partitions": 4, "plans": 2}


def test_parallel_free_parts_share_a_step_and_the_heaviest_stays():
    free = table("abc", {(0.0, 0.0, 1.0): "", (1.0, 0.0, 0.0): "ab"})
    search = run(free, (1.0, 5.0, 2.0))
    assert [s.parts for s in search.steps] == [("a", "c")]
    assert search.steps[0].rest == ("b",)
    # any partition of 3 unblocked parts is feasible: 3 splits, each child 1 plan
    assert and_or_graph(free).plans == 3


def test_subassembly_moved_as_a_unit_is_taken_apart_later():
    # along +z, a and b block each other and leave the heavy c together; along ±y all
    # three are strongly connected, but once c is gone b leaves a (the base) along -y
    tab = table(
        "abc",
        {
            (0.0, 0.0, 1.0): "ab ba ca cb",
            (0.0, 0.0, -1.0): "ab ba ac bc",
            (0.0, 1.0, 0.0): "ac ca cb ba",
            (0.0, -1.0, 0.0): "ac ca bc ab",
        },
    )
    search = run(tab, (1.0, 1.0, 9.0))
    assert [s.parts for s in search.steps] == [("a", "b"), ("b",)]
    assert search.steps[0].rest == ("c",)
    assert search.steps[1].rest == ("a",)
    assert tuple(search.steps[1].direction) == (0.0, -1.0, 0.0)


def test_extended_blocking_overrides_the_infinitesimal_bound():
    # Γ_t lets a and c leave the heavy x upwards, but along +z a sweeps into an overhang
    # of x (Γ_e): only c leaves, and a is then found stuck under x
    infinitesimal = table("acx", {(0.0, 0.0, 1.0): "", (1.0, 0.0, 0.0): "ax cx"})
    extended = table("acx", {(0.0, 0.0, 1.0): "ax", (1.0, 0.0, 0.0): "ax cx"})
    search = run(infinitesimal, (1.0, 1.0, 9.0), extended)
    assert [s.parts for s in search.steps] == [("c",)]
    assert search.steps[0].rest == ("a", "x")
    # c held nothing: a is blocked by x, which stays
    assert search.steps[0].blocking == ()
    assert search.locked == [0b101]


def test_interlocked_pair_is_reported():
    search = run(LOCKED, (1.0, 1.0))
    assert search.steps == []
    assert search.locked == [0b11]
    assert not separable(LOCKED, 0b11)
    assert separable(STACK, 0b111)
    assert and_or_graph(LOCKED).plans == 0


def test_minimal_interlocked_drops_free_parts():
    # p and q interlock; r rests on q and is free upwards
    tab = table("pqr", {(0.0, 0.0, 1.0): "pq qp qr", (1.0, 0.0, 0.0): "pq qp rq"})
    assert not separable(tab, 0b011)
    assert minimal_interlocked(tab, 0b011) == 0b011
    assert separable(tab, 0b111)
    # p-q and q-r both interlock: dropping p leaves the interlocked pair q, r
    chain = table("pqr", {(0.0, 0.0, 1.0): "pq qp qr rq", (1.0, 0.0, 0.0): "pq qp rq qr"})
    assert minimal_interlocked(chain, 0b111) == 0b110


def test_exploded_offsets_push_earlier_parts_further():
    search = run(STACK, (1.0, 1.0, 1.0))
    result = Plan(("a", "b", "c"), tuple(search.steps), (), None, 2)
    frames = result.exploded(10.0)
    assert len(frames) == 3
    assert np.allclose(frames[0]["c"], 0)
    assert np.allclose(frames[1]["c"], [0, 0, 10])
    assert np.allclose(frames[2]["c"], [0, 0, 20])
    assert np.allclose(frames[2]["b"], [0, 0, 10])
    assert np.allclose(frames[2]["a"], 0)
    assert result.order == (("b",), ("c",))
    data = result.to_dict()
    assert data["feasible"] is True
    assert data["stuck"] == []
    assert data["steps"][0] == {
        "parts": ["c"],
        "direction": [0.0, 0.0, 1.0],
        "axis": "+Z",
        "motion": "translation",
        "rest": ["a", "b"],
        "blocking": [["b", "c"]],
        "together": True,
    }


def assert_every_step_free(assembly: Assembly, result: Plan) -> None:
    """Each step checked on its own: the moved parts leave the rest by one extended
    translation (Wilson & Latombe 1992, "Extended translations"), each part against each
    part it leaves."""
    assert result.feasible, result.stuck
    # every part but the first base, or the fixed parts, moves at some step (a moved
    # group may split later)
    moved = set().union(*(step.parts for step in result.steps))
    if result.fixed:
        assert moved == set(assembly.names) - set(result.fixed)
    else:
        assert len(moved) == len(assembly.names) - 1
    tol = assembly.tolerance()
    for step in result.steps:
        assert np.isclose(np.linalg.norm(step.direction), 1.0)
        # on the ground, nothing goes down through it
        assert not result.ground or step.direction[2] >= -tol.angle
        for moving in step.parts:
            for rest in step.rest:
                assert extended_free(assembly, [moving], step.direction, tol, [moving, rest]), (
                    moving,
                    rest,
                )


def assert_free_by_cones(assembly: Assembly, result: Plan) -> None:
    """For convex parts, the cone test of :mod:`assemblykit.blocking.extended` is exact:
    an independent check of every step."""
    tol = assembly.tolerance()
    for step in result.steps:
        members = (*step.parts, *step.rest)
        dbg = extended_dbg(assembly, step.direction, members, tol)
        assert dbg.is_free(frozenset(step.parts)), step


def test_parts_leaving_and_groups_along_directions_visited_in_turn_are_the_extended_dbgs():
    # one search visits direction after direction, trying first the parts that blocked
    # each part along the others: who leaves and which groups close are those of the
    # DBG computed from scratch along each direction, for the whole gearbox and a subset
    assembly = shared_assembly(DEMO)
    names = tuple(assembly.names)
    tol = assembly.tolerance()
    translations = translation_table(assembly, tol)
    volumes = tuple(assembly.parts[n].volume for n in names)
    extended = ExtendedDirections(assembly, translations.directions, tol)
    rng = np.random.default_rng(11)
    everything = (1 << len(names)) - 1
    subset = everything & ~(1 << names.index("cover"))
    visited = rng.permutation(len(translations.directions))[:6].tolist()
    blocked_somewhere = False
    for members in (everything, subset):
        base = base_part(members, volumes)
        chosen = tuple(n for i, n in enumerate(names) if members >> i & 1)
        for k in visited:
            arcs = extended_dbg(assembly, translations.directions[k], chosen, tol).arcs
            held = {names.index(a) for a, _ in arcs}
            leaving = mask_of(i for i in range(len(names)) if members >> i & 1 and i not in held)
            assert extended.leaving(k, members, members) == leaving
            blocked_somewhere |= bool(held)
            union = DirectionTable.from_arcs(
                translations.names,
                translations.directions[[k]],
                [
                    list(translations.graph(k, members).edges)
                    + [(names.index(a), names.index(b)) for a, b in arcs]
                ],
            )
            whole = sorted(_removal(_sinks(union, 0, members), members, volumes))
            assert _free_closures(translations, extended, k, members, base) == whole
    assert blocked_somewhere


def test_gearbox_plan_lifts_pins_and_cover_first():
    assembly = shared_assembly(DEMO)
    result = plan(assembly)
    assert_every_step_free(assembly, result)
    first = result.steps[0]
    assert set(first.parts) == {"cover", "pin_1", "pin_2", "pin_3", "pin_4"}
    assert np.allclose(first.direction, UP)
    assert result.and_or is None


def test_the_assembly_order_reverses_the_gearbox_plan():
    data = plan(shared_assembly(DEMO), max_and_or_parts=0, max_hands=2).to_dict()
    assembly_steps = data["assembly_steps"]
    assert len(assembly_steps) == len(data["steps"])
    last = assembly_steps[-1]
    # the pins and cover come off first, so they go on last, downwards, each one held
    assert sorted(last["parts"]) == ["cover", "pin_1", "pin_2", "pin_3", "pin_4"]
    assert np.allclose(last["direction"], DOWN) and last["held"] == last["parts"]
    assert last["reverses"] == 1 and "base" in last["onto"]
    assert [step["parts"] for step in assembly_steps] == data["order"]
    assert data["gravity"] is None and "held" not in data["steps"][0]


@pytest.mark.parametrize(
    "path", ["compas_assembly/stack_assembly.json", "compas_assembly/arch_assembly.json"]
)
def test_masonry_plans_are_free_by_extended_translation(path):
    assembly = load_assembly(dataset(path))
    result = plan(assembly)
    assert_every_step_free(assembly, result)
    assert_free_by_cones(assembly, result)


@pytest.mark.slow
def test_asap_beam_plan_is_free_by_extended_translation():
    assembly = shared_assembly("asap_beam_assembly")
    result = plan(assembly)
    assert_every_step_free(assembly, result)
    assert result.and_or is not None and result.and_or.plans >= 1


def ring(radius: float, tube: float, transform: np.ndarray) -> trimesh.Trimesh:
    mesh = trimesh.creation.torus(radius, tube, major_sections=48, minor_sections=12)
    mesh.apply_transform(transform)
    return mesh


def test_interlocked_rings_are_stuck():
    # two chain links: the second ring is turned into the xz plane and threaded through
    first = ring(10.0, 2.0, np.eye(4))
    turn = trimesh.transformations.rotation_matrix(np.pi / 2, [1, 0, 0])
    turn[:3, 3] = [10.0, 0.0, 0.0]
    second = ring(10.0, 2.0, turn)
    assembly = Assembly([Part("ring_a", first), Part("ring_b", second)])
    result = plan(assembly)
    data = result.to_dict()
    assert data["feasible"] is False
    assert data["stuck"] == ["ring_a", "ring_b"]
    assert data["steps"] == []
    lock = result.interlocked[0]
    # the rings do not touch: nothing blocks infinitesimal motions
    assert lock.translation_locked is False
    assert lock.rigid_may_free is True
    assert result.and_or is not None and result.and_or.plans == 0


def test_the_interlock_reported_is_the_least_one_the_whole_dbgs_give():
    # a chain of three links and a block lying on the table: the search stops on the
    # chain; the interlock named, found from Γ_t and Γ_e along the directions where Γ_t
    # separates, is the one the whole Γ_e DBGs of every direction give (the first two
    # links: dropping the first leaves the last two, still linked, dropping either then
    # frees the other)
    first = ring(10.0, 2.0, np.eye(4))
    turn = trimesh.transformations.rotation_matrix(np.pi / 2, [1, 0, 0])
    turn[:3, 3] = [10.0, 0.0, 0.0]
    third = np.eye(4)
    third[:3, 3] = [20.0, 0.0, 0.0]
    block = trimesh.creation.box((4.0, 4.0, 4.0))
    block.apply_translation([-30.0, 0.0, 0.0])
    parts = [
        Part("ring_a", first),
        Part("ring_b", ring(10.0, 2.0, turn)),
        Part("ring_c", ring(10.0, 2.0, third)),
        Part("block", block),
    ]
    assembly = Assembly(parts)
    tol = assembly.tolerance()
    translations = translation_table(assembly, tol)
    members = mask_of(range(4))
    whole = ExtendedDirections(assembly, translations.directions, tol)
    expected = minimal_interlocked(whole.table(translations.incomplete(members), members), members)
    lazy = ExtendedDirections(assembly, translations.directions, tol)
    found = least_interlocked(translations, lazy, members)
    assert found == expected == mask_of([1, 2])
    (lock,) = plan(assembly).interlocked
    assert lock.parts == ("ring_b", "ring_c") and lock.held == ("ring_a",)


@pytest.mark.slow
def test_crossvault_plan_takes_all_184_blocks_apart():
    assembly = shared_assembly("compas_assembly/crossvault_assembly.json")
    result = plan(assembly)
    assert len(assembly.names) == 184
    assert_every_step_free(assembly, result)
    # the vault is taken down from the top: the first step lifts blocks of the crown (how
    # many of the 20 crown blocks free upward it groups depends on floating-point ties)
    tops = {name: assembly[name].mesh.bounds[1, 2] for name in assembly.names}
    crown = max(tops.values())
    assert np.allclose(result.steps[0].direction, UP)
    assert result.steps[0].parts
    assert all(np.isclose(tops[name], crown) for name in result.steps[0].parts)
    assert len(result.steps) <= 40


def test_large_assemblies_take_candidates_from_each_parts_own_arrangement(monkeypatch):
    assembly = load_assembly(dataset("compas_assembly/arch_assembly.json"))
    tol = assembly.tolerance()
    whole = translation_table(assembly, tol)
    terms = blocking_terms(assembly, "infinitesimal", tol)
    local = local_table(tuple(assembly.names), terms, tol)
    # along every local direction, Γ_t is the NDBG's DBG there
    ndbg = blocking_graph(assembly, "infinitesimal", tol=tol)
    for k in range(0, len(local.directions), 7):
        arcs = {(local.names[i], local.names[j]) for i, j in local.graph(k, (1 << 30) - 1).edges}
        assert arcs == set(ndbg.dbg(local.directions[k]).arcs)
    # every part that Γ_t lets leave the whole arch along some region leaves along some
    # local direction
    everything = (1 << len(assembly.names)) - 1
    assert set(np.flatnonzero(whole.free_parts(everything).any(axis=0))) == set(
        np.flatnonzero(local.free_parts(everything).any(axis=0))
    )
    monkeypatch.setattr(tables, "FULL_ARRANGEMENT_REGIONS", 0)
    result = plan(assembly)
    assert result.directions == len(local.directions)
    assert_every_step_free(assembly, result)


PLANAR = ROOT / "src" / "assemblykit" / "examples" / "planar"


def test_planar_peg_leaves_the_hook_at_the_low_end_of_its_free_arc():
    from assemblykit.io.polygons import load_polygons

    # the peg is free on [atan(1/3), 45 deg] (tests/blocking/test_polygons.py); of the
    # regions there, the end point (3, 1)/sqrt(10) is the closest to a coordinate axis
    result = plan(load_polygons(PLANAR / "hook.yaml"))
    assert result.feasible
    (step,) = result.steps
    assert step.parts == ("peg",) and step.rest == ("hook",)
    assert np.allclose(step.direction, np.array([3.0, 1.0, 0.0]) / np.sqrt(10))
    assert result.to_dict()["order"] == [["peg"]]
    assert result.and_or is not None and result.and_or.plans == 1


def test_stuck_lists_the_part_trapped_behind_an_interlock():
    from assemblykit.io.polygons import load_polygons

    # bottle and plug interlock (the foot is wider than the neck, the stem fills it);
    # the block leaves the bottle alone (up the neck) and the plug alone (down), but
    # not the two: all three are stuck, the block held by the minimal interlock
    model = load_polygons(PLANAR / "bottle.yaml")
    result = plan(model)
    assert not result.feasible
    assert result.stuck == ("block", "bottle", "plug")
    (lock,) = result.interlocked
    assert lock.parts == ("bottle", "plug")
    assert lock.held == ("block",)
    # the foot hangs: an infinitesimal translation down may start, none with rotation
    assert lock.translation_locked is False
    assert lock.rigid_may_free is False
    data = result.to_dict()
    assert data["stuck"] == ["block", "bottle", "plug"]
    assert data["interlocked"][0]["held"] == ["block"]
    # consistent with blocking: no proper part of the stuck set is removable (Γ_e is
    # exact for polygons), while each pair with the block is separable
    assert blocking_graph(model, "extended", parts=result.stuck).removable() == []
    for other in ("bottle", "plug"):
        assert blocking_graph(model, "extended", parts=["block", other]).removable()


def test_a_cube_in_a_one_piece_cage_leaves_through_the_diagonal_tunnel():
    import sys

    sys.path.insert(0, str(ROOT / "tests" / "blocking"))
    from test_extended import APERTURE, DIAGONAL, caged_cube

    from assemblykit.blocking.queries import can_extract

    asm = caged_cube()
    result = plan(asm)
    assert result.feasible
    (step,) = result.steps
    assert step.parts == ("cube",) and step.rest == ("cage",)
    # within the tunnel's aperture around its axis (derived in test_extended)
    assert np.arccos(np.clip(step.direction @ DIAGONAL, -1, 1)) < APERTURE
    assert extended_free(asm, ["cube"], step.direction, asm.tolerance())
    assert can_extract(asm, ["cube"]) is not None


@pytest.mark.parametrize("through", [False, True])
def test_a_rod_in_a_half_round_groove_is_planned_out_of_it(through: bool):
    from curved_parts import DISTANCES, rod_in_groove, swept_overlaps

    asm = rod_in_groove(through)
    result = plan(asm)
    assert result.feasible
    (step,) = result.steps
    assert step.parts == ("rod",)
    # the groove frees d_x = 0, d_z >= 0; its closed ends leave only +z
    assert abs(step.direction[0]) < 1e-6 and step.direction[2] >= -1e-6
    if not through:
        np.testing.assert_allclose(step.direction, [0.0, 0.0, 1.0], atol=1e-6)
    volumes, touching = swept_overlaps(asm, "rod", step.direction, DISTANCES)
    assert np.all(volumes <= touching)


def test_plan_blocking_and_motion_agree_that_the_ball_joint_ball_lifts_out():
    from assemblykit.motion.freedom import part_motion
    from curved_parts import BALL_JOINT, DISTANCES, swept_overlaps

    asm = load_assembly(BALL_JOINT / "ball_joint.yaml")
    result = plan(asm)
    assert result.feasible and result.stuck == ()
    first = result.steps[0]
    assert first.parts == ("ball",)
    # up, inside the cone above the cup's rim (0.2 of the radius below the centre)
    assert first.direction[2] >= np.sqrt(1.0 - 0.2**2) - 1e-3
    assert any(r.parts == {"ball"} for r in blocking_graph(asm, "infinitesimal").removable())
    reading = part_motion(asm, "ball").unilateral
    assert reading.can_lift_off and min(r[2] for r in reading.lift_off) > 0.97
    volumes, touching = swept_overlaps(asm, "ball", first.direction, DISTANCES)
    assert np.all(volumes <= touching)


@pytest.mark.slow
def test_the_ball_joint_ball_is_removable_in_the_whole_extended_ndbg():
    # every sampled direction's Γ_e of the curved parts (seconds): the ball leaves alone
    from curved_parts import BALL_JOINT

    asm = load_assembly(BALL_JOINT / "ball_joint.yaml")
    assert any(r.parts == {"ball"} for r in blocking_graph(asm, "extended").removable())


@pytest.mark.parametrize(
    ("path", "directions"),
    [(DEMO, None), (dataset("compas_assembly/crossvault_assembly.json"), 4)],
)
@pytest.mark.slow
def test_groups_found_from_infinitesimal_sinks_are_the_extended_dbgs_sinks(path, directions):
    # the minimal sets free in Γ_t and Γ_e that leave the base, found as closures of
    # Γ_t's sink components, are the sink components of the union of the whole DBGs,
    # along candidate directions (all, or some at random) of the whole assembly and of
    # random subassemblies; some are groups
    assembly = load_assembly(path)
    tol = assembly.tolerance()
    translations = translation_table(assembly, tol)
    volumes = tuple(assembly.parts[n].volume for n in assembly.names)
    rng = np.random.default_rng(5)
    count = len(assembly.names)
    subsets = [np.flatnonzero(rng.random(count) < 0.7).tolist() for _ in range(5)]
    groups = 0
    for kept in [list(range(count)), *subsets]:
        members = mask_of(kept)
        base = base_part(members, volumes)
        extended = ExtendedDirections(assembly, translations.directions, tol)
        chosen = rng.permutation(len(translations.directions))[:directions]
        for k in chosen.tolist():
            union = DirectionTable.from_arcs(
                translations.names,
                translations.directions[[k]],
                [list(translations.graph(k, members).edges) + extended.arcs(k, members)],
            )
            whole = sorted(_removal(_sinks(union, 0, members), members, volumes))
            fresh = ExtendedDirections(assembly, translations.directions, tol)
            assert _free_closures(translations, fresh, k, members, base) == whole
            groups += sum(several(s) for s in whole)
    assert groups


def test_a_narrower_is_asked_about_the_groups_of_at_most_sixteen_directions():
    # along each of 40 directions a and b block each other and may leave the heavy c
    # together; a narrower that rejects every set (no removal stands) is asked about
    # the groups of 16 directions, then no more groups are tried
    angles = np.linspace(0.0, 1.0, 40)
    tab = table("abc", {(float(np.cos(t)), float(np.sin(t)), 0.0): "ab ba" for t in angles})
    asked = []

    def reject(members: int, k: int, sets: list[int]) -> list[int]:
        asked.append(sets)
        return []

    assert _choose_removal(BlockedRows(tab), tab, 0b111, (1.0, 1.0, 9.0), None, reject) is None
    assert asked == [[0b011]] * GROUP_REJECTIONS
    assert GROUP_REJECTIONS == 16
    # without a narrower the pair leaves
    assert _choose_removal(BlockedRows(tab), tab, 0b111, (1.0, 1.0, 9.0), None) == (0, [0b011])


def test_a_narrower_is_not_asked_along_directions_that_cannot_win():
    # a, b and c may leave the heavy x along a diagonal, a and b along +x and along a
    # steeper diagonal; a narrower picks one part, so after +x (the axis) no direction
    # freeing one part can beat it and the steeper diagonal is not asked about
    tab = table(
        "abcx",
        {(0.6, 0.8, 0.0): "", (1.0, 0.0, 0.0): "cx", (0.0, 0.8, 0.6): "cx"},
    )
    asked = []

    def first(members: int, k: int, sets: list[int]) -> list[int]:
        asked.append(k)
        return sets[:1]

    volumes = (1.0, 1.0, 1.0, 9.0)
    assert _choose_removal(BlockedRows(tab), tab, 0b1111, volumes, None, first) == (1, [0b0001])
    assert asked == [0, 1]


def test_parts_a_narrower_already_rejected_get_no_extended_blocking():
    # a and b may leave the heavy c along +x, a and d along +y; the narrower rejects a
    # and b (their removal would not stand) and admits d: along +y only d is tested
    # against extended blocking, and d leaves
    tab = table("abdc", {(1.0, 0.0, 0.0): "dc", (0.0, 1.0, 0.0): "bc"})
    tested: list[int] = []

    class Spy:
        def blockers(self, k: int, movers: int, among: int) -> dict[int, int]:
            tested.append(movers)
            return tab.blockers(k, movers, among)

    judged: dict[int, bool] = {}

    def admits(members: int, mask: int) -> bool:
        judged[mask] = mask == 0b0100
        return judged[mask]

    narrow = FirstAdmitted(
        sorted, admits, lambda members: sum(m for m, ok in judged.items() if not ok)
    )
    volumes = (1.0, 1.0, 1.0, 9.0)
    assert _choose_removal(BlockedRows(tab), Spy(), 0b1111, volumes, None, narrow) == (1, [0b0100])  # type: ignore[arg-type]
    assert tested == [0b0011, 0b0100]
    assert judged == {0b0001: False, 0b0010: False, 0b0100: True}


def test_a_stopped_set_names_its_interfering_pairs_with_their_volumes():
    # a peg 0.2 wide pressed 0.1 deep into the wall of a cup it sits in: no shape
    # interlock holds it, their shared 0.2 x 0.1 x 1 block does
    cup = trimesh.boolean.difference(
        [box((3, 3, 2), (0, 0, 0)), box((1, 1, 2), (1, 1, 1))], engine="manifold"
    )
    peg = box((1.1, 0.2, 1), (1, 1.4, 1))
    result = plan(Assembly([Part("cup", cup), Part("peg", peg)]), max_and_or_parts=0)
    assert not result.feasible and set(result.stuck) == {"cup", "peg"}
    (lock,) = result.interlocked
    ((a, b, volume),) = lock.interfering
    assert {a, b} == {"cup", "peg"} and volume == pytest.approx(0.1 * 0.2 * 1.0, rel=1e-9)
    assert lock.reason.startswith("interfering (") and "0.02" in lock.reason
    assert result.to_dict()["interlocked"][0]["interfering"][0]["volume"] == pytest.approx(0.02)


def test_a_chain_of_plates_drawn_overlapping_leaves_as_one_and_names_an_interfering_pair():
    # three 10 x 10 x 1 plates in one layer on a base, each drawn 4 into the next (40%
    # of a plate: more than a designed share, so left as they are): no translation
    # parts two plates that share a volume, so the chain lifts off as one (+z), the plan
    # is not feasible, and the interlock it names is the first such pair, (a, b), which
    # manifold3d finds sharing 4 x 10 x 1 = 40
    base = box((30, 14, 1), (-2, -2, 0))
    plates = {name: box((10, 10, 1), (x, 0, 1)) for name, x in (("a", 0), ("b", 6), ("c", 12))}
    drawn = Assembly([Part("base", base), *(Part(n, m) for n, m in plates.items())])
    shared = trimesh.boolean.intersection([plates["a"], plates["b"]], engine="manifold")
    assert shared.volume == pytest.approx(40.0)
    prepared = resolve_overlaps(drawn)
    assert {(o.a, o.b, o.resolution) for o in prepared.overlaps} == {("a", "b", ""), ("b", "c", "")}
    result = plan(prepared, max_and_or_parts=0)
    assert not result.feasible and sorted(result.stuck) == ["a", "b", "c"]
    (step,) = result.steps
    assert sorted(step.parts) == ["a", "b", "c"] and step.rest == ("base",)
    np.testing.assert_allclose(step.direction, [0.0, 0.0, 1.0], atol=1e-9)
    (lock,) = result.interlocked
    assert lock.parts == ("a", "b") and {(a, b) for a, b, _ in lock.interfering} == {
        ("a", "b"),
        ("b", "c"),
    }
    assert_steps_clear(prepared, result)


def test_a_direction_a_hair_off_an_axis_is_taken_along_the_axis(monkeypatch):
    """A block hung on a pin in a U-shaped frame, 1 apart from it everywhere: block and
    pin leave together along +z (or along y). The candidate directions are tilted by
    0.003 rad about x (the arrangement's points inside their regions, off the circles
    through an axis, as a pin's tessellated contact gives on a STEP file): the step
    still goes along +z exactly, which leaves the frame as clear (the steps are checked
    by their extended translations and by sweeps); tilted by 0.05 rad, beyond the snap,
    it keeps the candidate."""
    hole = trimesh.creation.cylinder(3.0, 40.0, sections=24)
    hole.apply_transform(trimesh.transformations.rotation_matrix(np.pi / 2, [0, 1, 0]))
    hole.apply_translation([0, 0, 10])
    block = trimesh.creation.box([20, 20, 20])
    block.apply_translation([0, 0, 10])
    block = block.difference(hole, engine="manifold")
    pin = trimesh.creation.cylinder(3.0, 20.0, sections=24)
    pin.apply_transform(trimesh.transformations.rotation_matrix(np.pi / 2, [0, 1, 0]))
    pin.apply_translation([0, 0, 10])
    sides = [trimesh.creation.box([5, 60, 36]) for _ in range(2)]
    sides[0].apply_translation([-13.5, 0, 7])
    sides[1].apply_translation([13.5, 0, 7])
    floor = trimesh.creation.box([32, 60, 5])
    floor.apply_translation([0, 0, -3.5])
    frame = trimesh.boolean.union([*sides, floor], engine="manifold")
    assembly = Assembly([Part("frame", frame), Part("block", block), Part("pin", pin)])
    original = tables.translation_table

    def tilted_by(angle: float):
        turn = trimesh.transformations.rotation_matrix(angle, [1, 0, 0])[:3, :3]

        def tilted(*args, **kwargs):
            found = original(*args, **kwargs)
            return dataclasses.replace(found, directions=found.directions @ turn.T)

        return tilted

    for angle, expected in ((0.003, [0.0, 0.0, 1.0]), (0.05, None)):
        monkeypatch.setattr(planner, "translation_table", tilted_by(angle))
        result = plan(assembly)
        lift = [s for s in result.steps if set(s.parts) == {"block", "pin"}]
        assert len(lift) == 1, result.steps
        if expected is None:
            assert lift[0].direction[2] == pytest.approx(np.cos(0.05), abs=1e-12)
        else:
            assert lift[0].direction.tolist() == expected
        assert_every_step_free(assembly, result)
        assert_steps_clear(assembly, result)
