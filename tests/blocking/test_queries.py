"""Questions answered by the NDBG (seed 004, introduction and conclusion)."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh
from blocking_helpers import ContactAssembly, box, cylinder, mesh_assembly, square
from test_extended import ring

from assemblykit.blocking.queries import (
    can_extract,
    locally_free_directions,
    parts_to_remove_before,
    removable_parts,
    removable_subassemblies,
    separable_by_translations,
)
from assemblykit.errors import UnknownNameError
from assemblykit.geometry.contacts import Contact

GAP = 0.01


def boxed() -> object:
    """A crate (floor and four walls, one mesh of convex pieces) in a tray, a box
    inside it with small gaps, and a lid over both."""
    crate = trimesh.util.concatenate(
        [
            box([0, 0, 0], [3, 3, 0.5]),
            box([0, 0, 0.5], [0.5, 3, 2]),
            box([2.5, 0, 0.5], [3, 3, 2]),
            box([0.5, 0, 0.5], [2.5, 0.5, 2]),
            box([0.5, 2.5, 0.5], [2.5, 3, 2]),
        ]
    )
    return mesh_assembly(
        {
            "crate": crate,
            "inside": box([0.5 + GAP, 0.5 + GAP, 0.5 + GAP], [2.5 - GAP, 2.5 - GAP, 2 - GAP]),
            "lid": box([0, 0, 2 + GAP], [3, 3, 2.5]),
            "tray": trimesh.util.concatenate(
                [
                    box([-1, -1, -1], [4, 4, -GAP]),
                    box([-1, -1, -GAP], [-GAP, 4, 1]),
                    box([3 + GAP, -1, -GAP], [4, 4, 1]),
                    box([-GAP, -1, -GAP], [3 + GAP, -GAP, 1]),
                    box([-GAP, 3 + GAP, -GAP], [3 + GAP, 4, 1]),
                ]
            ),
        }
    )


def test_box_in_crate_needs_the_lid_removed_first():
    asm = boxed()
    assert can_extract(asm, ["inside"]) is None
    lid = can_extract(asm, ["lid"])
    assert lid is not None and any(np.allclose(d, [0, 0, 1]) for d in lid.directions)
    # any other way the box pushes the crate and the tray: the lid alone is cheaper
    assert parts_to_remove_before(asm, "inside") == frozenset({"lid"})
    assert parts_to_remove_before(asm, "lid") == frozenset()
    assert separable_by_translations(asm)
    singles = {r.parts for r in removable_parts(asm)}
    assert frozenset({"lid"}) in singles and frozenset({"inside"}) not in singles
    sets = {r.parts for r in removable_subassemblies(asm)}
    assert frozenset({"lid"}) in sets and frozenset({"inside", "lid"}) in sets
    with pytest.raises(UnknownNameError):
        can_extract(asm, ["nothing"])


def test_interlocked_rings_do_not_come_apart():
    asm = mesh_assembly({"r1": ring([0, 0, 0], "xy"), "r2": ring([1.25, 0, 0], "xz")})
    assert not separable_by_translations(asm)
    assert can_extract(asm, ["r1"]) is None
    assert removable_parts(asm) == []


def test_peg_extraction_directions_for_each_motion():
    contact = Contact(
        "peg",
        "block",
        planar=(square([0, 0, -1], (0, 0, -1)),),
        curved=(cylinder([0, 0, 1], "peg"),),
    )
    asm = ContactAssembly(["peg", "block"], [contact])
    found = can_extract(asm, ["peg"], "infinitesimal")
    assert found is not None and len(found.directions) == 1
    assert np.allclose(found.directions[0], [0, 0, 1])
    (d,) = locally_free_directions(asm, ["peg"])
    assert np.allclose(d, [0, 0, 1])
    twist = can_extract(asm, ["peg"], "rigid")
    assert twist is not None
    # the only freeing twists are along +z, possibly with a spin about the axis
    assert twist.directions[0][5] > 0
    assert np.allclose(twist.directions[0][[3, 4]], 0, atol=1e-9)
