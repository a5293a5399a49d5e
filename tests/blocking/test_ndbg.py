"""Γ_t: NDBG for infinitesimal translations, crossing rule against direct DBGs (Wilson & Latombe
1992)."""

from __future__ import annotations

import numpy as np
import pytest
from blocking_helpers import ContactAssembly, compas_folder, cylinder, random_box_contacts, square

from assemblykit.blocking.graphs import blocking_graph
from assemblykit.geometry.contacts import Contact, assembly_contacts
from assemblykit.io.polygons import load_polygons
from assemblykit.model.polygons import PolygonAssembly


def crossing_equals_direct(g) -> None:
    for region in g.regions():
        assert region.dbg.arcs == g.dbg(region.direction).arcs, region


def boundary_property(g) -> None:
    """An arc present in a region is present in every region it bounds (Wilson & Latombe 1992)."""
    arr = g.arrangement
    for low, high in zip(arr.links_low, arr.links_high, strict=True):
        assert g.region_dbg(low).arcs <= g.region_dbg(high).arcs


def test_block_on_table_is_free_in_the_closed_upper_hemisphere():
    asm = ContactAssembly(
        ["table", "block"], [Contact("table", "block", planar=(square([0, 0, 1]),))]
    )
    g = blocking_graph(asm)
    assert g.arrangement.counts == {"vertices": 0, "edges": 1, "faces": 2}
    removal = {r.parts: r for r in g.removable()}[frozenset({"block"})]
    dirs = np.array(removal.directions)
    assert np.all(dirs[:, 2] >= 0) and len(dirs) == 2  # upper face and the equator
    for d in ([0, 0, 1], [1, 0, 0], [0.3, -0.2, 0.9]):
        assert g.dbg(d).is_free({"block"})
    assert not g.dbg([0.0, 0.1, -1.0]).is_free({"block"})
    crossing_equals_direct(g)


def test_peg_in_blind_hole_is_free_only_outward_along_the_axis():
    # peg's outward normal at the hole bottom points down into the block
    contact = Contact(
        "peg",
        "block",
        planar=(square([0, 0, -1], (0, 0, -1)),),
        curved=(cylinder([0, 0, 1], "peg"),),
    )
    g = blocking_graph(ContactAssembly(["peg", "block"], [contact]))
    removal = {r.parts: r for r in g.removable()}[frozenset({"peg"})]
    assert len(removal.directions) == 1
    assert np.allclose(removal.directions[0], [0, 0, 1])
    assert not g.dbg([0, 0, -1]).is_free({"peg"})
    assert not g.dbg([1e-3, 0, 1]).is_free({"peg"})
    crossing_equals_direct(g)


def test_spherical_contact_blocks_every_direction():
    from assemblykit.geometry.contacts import CurvedPatch

    ball = CurvedPatch("spherical", np.zeros(3), None, 1.0, "ball")
    g = blocking_graph(
        ContactAssembly(["ball", "socket"], [Contact("ball", "socket", curved=(ball,))])
    )
    assert g.removable() == []
    crossing_equals_direct(g)


@pytest.mark.parametrize("seed", range(4))
def test_random_boxes_crossing_rule_equals_direct(seed):
    g = blocking_graph(random_box_contacts(np.random.default_rng(seed), 7, 14))
    crossing_equals_direct(g)
    boundary_property(g)


def test_planar_partition_has_4k_regions_and_crossing_equals_direct():
    # Fig. 1-like: three distinct contact directions (horizontal, vertical, slanted)
    polygons = {
        "base": [[0, 0], [4, 0], [4, 1], [0, 1]],
        "left": [[0, 1], [1, 1], [1, 3], [0, 3]],
        "wedge": [[1, 1], [3, 1], [1, 3]],
        "roof": [[1, 3], [3, 1], [4, 1], [4, 4], [0, 4], [0, 3]],
    }
    asm = PolygonAssembly({k: np.array(v, dtype=float) for k, v in polygons.items()})
    contacts = assembly_contacts(asm)
    normals = {tuple(np.round(np.abs(p.normal), 6)) for c in contacts for p in c.planar}
    assert len(normals) == 3
    g = blocking_graph(asm)
    assert g.arrangement.counts == {"vertices": 6, "edges": 6, "faces": 0}
    crossing_equals_direct(g)
    boundary_property(g)
    # the wedge is enclosed by base, left and roof: it is free in no direction
    assert frozenset({"wedge"}) not in {r.parts for r in g.removable()}
    # the roof lifts straight up
    assert g.dbg([0, 1]).is_free({"roof"})


def test_polygon_yaml(tmp_path):
    path = tmp_path / "p.yaml"
    path.write_text("parts:\n  a: [[0,0],[1,0],[1,1],[0,1]]\n  b: [[1,0],[2,0],[2,1],[1,1]]\n")
    asm = load_polygons(path)
    (contact,) = assembly_contacts(asm)
    assert np.allclose(contact.planar[0].normal, [1, 0, 0])
    assert contact.planar[0].area == pytest.approx(1.0)
    g = blocking_graph(asm)
    assert g.arrangement.counts == {"vertices": 2, "edges": 2, "faces": 0}
    assert g.dbg([1, 0]).arcs == frozenset({("a", "b")})


def test_a_subassembly_has_the_arcs_of_the_whole_among_its_parts():
    # a sub-assembly's graph, asked before or after the whole one, has exactly the
    # arcs of the whole graph between its own parts, in every direction asked
    asm = random_box_contacts(np.random.default_rng(5), 6, 10)
    early = blocking_graph(asm, parts=["p3", "p4"])
    full = blocking_graph(asm)
    sub = blocking_graph(asm, parts=["p0", "p1", "p2"])
    derived = blocking_graph(asm, parts=["p1", "p4", "p5"])
    assert sub.parts == ("p0", "p1", "p2")
    for d in np.random.default_rng(6).normal(size=(20, 3)):
        arcs = full.dbg(d).arcs
        for graph in (early, sub, derived):
            inside = set(graph.parts)
            assert graph.dbg(d).arcs == {a for a in arcs if set(a) <= inside}
    crossing_equals_direct(derived)


def test_incremental_removal_and_addition_match_recomputation():
    asm = random_box_contacts(np.random.default_rng(7), 6, 14)
    full = blocking_graph(asm)
    rest = [n for n in asm.names if n != "p3"]
    smaller = full.without_parts(["p3"])
    for region in smaller.regions():
        assert region.dbg.arcs == smaller.dbg(region.direction).arcs
        assert region.dbg.arcs == {a for a in full.dbg(region.direction).arcs if "p3" not in a}
    # adding p3 back: its contacts lie on existing circles, so only its slots are evaluated
    from assemblykit.blocking.constraints import infinitesimal_terms

    back_contacts = [c for c in asm.given if "p3" in c.pair]
    regrown = smaller.with_terms(["p3"], infinitesimal_terms(back_contacts), len(back_contacts))
    assert regrown.arrangement is smaller.arrangement
    for region in regrown.regions():
        assert region.dbg.arcs == full.dbg(region.direction).arcs
    assert set(rest) < set(regrown.parts)
    # slots stay grouped by moving part with valid part indices; pads never block
    for g in (smaller, regrown):
        moving, blocker = g.table.slot_moving, g.table.slot_blocker
        assert np.all(np.diff(moving) >= 0)
        assert min(moving.min(), blocker.min()) >= 0
        assert max(moving.max(), blocker.max()) < len(g.parts)
        slots = np.unpackbits(g.packed, axis=1, count=len(moving)).astype(bool)
        assert not slots[:, moving == blocker].any()
    assert (smaller.table.slot_moving == smaller.table.slot_blocker).sum() > 0
    # the old slots did not move: the new part's arcs went into pads and after them
    old = len(smaller.table.starts)
    assert np.array_equal(regrown.table.slot_moving[:old], smaller.table.slot_moving)


def test_compas_stack_and_arch_crossing_rule_equals_direct():
    from assemblykit import load_assembly

    folder = compas_folder()
    for name in ("stack_assembly.json", "arch_assembly.json"):
        asm = load_assembly(folder / name)
        g = blocking_graph(asm)
        assert g.contacts == len(asm.contacts()) > 0
        crossing_equals_direct(g)
        boundary_property(g)
    # the top of the stack lifts off; nothing else of the stack lifts alone
    stack = load_assembly(folder / "stack_assembly.json")
    g = blocking_graph(stack)
    up = g.dbg([0, 0, 1])
    tops = [p for p in stack.names if up.is_free({p})]
    assert len(tops) == 1


def test_to_dict_contract():
    asm = ContactAssembly(
        ["table", "block"], [Contact("table", "block", planar=(square([0, 0, 1]),))]
    )
    out = blocking_graph(asm).to_dict()
    assert out["parts"] == ["table", "block"]
    assert out["contacts"] == 1
    assert out["regions"] == {"vertices": 0, "edges": 1, "faces": 2}
    first = out["removable"][0]
    assert set(first) == {"parts", "directions"}
    assert all(
        abs(np.linalg.norm(d) - 1) < 1e-12 for r in out["removable"] for d in r["directions"]
    )


def test_cross_section_of_stacked_boxes():
    from assemblykit.geometry.polygons import section_polygons
    from assemblykit.model.packings import box_mesh as box

    meshes = {"low": box([0, 0, 0], [2, 1, 1]), "high": box([0.5, 0, 1], [1.5, 1, 2])}
    planar = section_polygons(meshes, np.array([0, 0.5, 0]), np.array([0, 1.0, 0]))
    assert sorted(planar.names) == ["high", "low"]
    (contact,) = assembly_contacts(planar)
    (patch,) = contact.planar
    assert patch.area == pytest.approx(1.0)
    g = blocking_graph(planar)
    assert g.arrangement.counts == {"vertices": 2, "edges": 2, "faces": 0}
    # lifting the upper box in the section plane frees it, pushing it down does not
    lift = [d for d in g.arrangement.directions if abs(d @ patch.normal) > 0.5]
    free = [g.dbg(d[:2]).is_free({"high"}) for d in lift]
    assert sorted(free) == [False, True]


def test_adding_a_part_on_new_planes_rebuilds_exactly():
    from assemblykit.blocking.constraints import infinitesimal_terms

    asm = random_box_contacts(np.random.default_rng(11), 5, 8)
    g = blocking_graph(asm).without_parts(["p4"])
    fresh = [Contact("q", "p0", planar=(square([0.3, -0.4, 0.87]),))]
    grown = g.with_terms(["q"], infinitesimal_terms(fresh), 1)
    assert grown.arrangement is not g.arrangement  # a new plane: rebuilt
    assert np.any(
        np.abs(
            grown.table.normals @ np.array([0.3, -0.4, 0.87]) / np.linalg.norm([0.3, -0.4, 0.87])
        )
        > 1 - 1e-12
    )
    crossing_equals_direct(grown)
    d = np.array([0.3, -0.4, 0.87])
    assert grown.dbg(d).blocks("p0", "q") and not grown.dbg(-d).blocks("p0", "q")
    assert "p4" not in grown.parts
