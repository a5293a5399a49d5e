"""Questions answered by the NDBG (Wilson & Latombe 1992, introduction and conclusion)."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh
from blocking_helpers import ContactAssembly, cylinder, mesh_assembly, square
from test_extended import ring

from assemblykit.blocking.extended import extended_dbg, extended_free
from assemblykit.blocking.queries import (
    can_extract,
    locally_free_directions,
    parts_to_remove_before,
    removable_parts,
    removable_subassemblies,
    removal_before,
)
from assemblykit.errors import UnknownNameError
from assemblykit.geometry.contacts import Contact
from assemblykit.model.packings import box_mesh as box
from assemblykit.model.packings import guillotine_packing
from assemblykit.planning.planner import plan, separable_by_translations

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


def cup(half: float, wall: float, bottom: float, top: float) -> trimesh.Trimesh:
    """An open square cup (one non-convex body): outer half-size ``half``, walls and floor
    ``wall`` thick, from ``bottom`` to ``top``."""
    import manifold3d

    outer = manifold3d.Manifold.cube([2 * half, 2 * half, top - bottom]).translate(
        [-half, -half, bottom]
    )
    inner = half - wall
    hollow = manifold3d.Manifold.cube([2 * inner, 2 * inner, top - bottom]).translate(
        [-inner, -inner, bottom + wall]
    )
    mesh = (outer - hollow).to_mesh()
    return trimesh.Trimesh(mesh.vert_properties[:, :3], mesh.tri_verts)


def nested_cups() -> object:
    """A table, an outer cup on it (inside half-size 1.8, rim at z = 2), an inner cup on
    its floor (half-size 1.7, rim at 1.7) and a lid on the outer rim."""
    return mesh_assembly(
        {
            "table": box([-5, -5, -1], [5, 5, 0]),
            "outer": cup(2.0, 0.2, 0.0, 2.0),
            "inner": cup(1.7, 0.2, 0.2, 1.7),
            "lid": box([-2, -2, 2], [2, 2, 2.3]),
        }
    )


def test_nested_cups_need_only_the_lid_removed_over_all_directions():
    asm = nested_cups()
    # by hand: the inner cup is blocked upwards by the lid only, sideways by the outer
    # cup only (its walls 0.1 away), downwards by the outer cup and the table. The outer
    # cup cannot leave first: the inner cup is inside it, the table under it. So {lid}
    # (up) is the only removable set of one part; {outer} is as small but not removable.
    found = removal_before(asm, "inner")
    assert found.parts == frozenset({"lid"}) and found.minimal
    assert found.direction is not None and found.direction[2] > 0
    assert parts_to_remove_before(asm, "inner") == frozenset({"lid"})
    assert parts_to_remove_before(asm, "lid") == frozenset()
    assert can_extract(asm, ["inner"]) is None
    assert separable_by_translations(asm)


def swept_free(asm, moving, rest, direction, threshold: float) -> bool:
    """Independent sweep (manifold3d): the moving parts translated in steps of a quarter
    of their smallest extent along ``direction`` until past the bounding box never share
    more than ``threshold`` of volume with the rest."""
    import manifold3d

    def solid(names):
        total = manifold3d.Manifold()
        for name in names:
            mesh = asm.parts[name].mesh
            total += manifold3d.Manifold(
                manifold3d.Mesh(
                    np.asarray(mesh.vertices, dtype=np.float32),
                    np.asarray(mesh.faces, dtype=np.uint32),
                )
            )
        return total

    mover, others = solid(moving), solid(rest)
    extent = min(np.ptp(asm.parts[n].mesh.bounds, axis=0).min() for n in moving)
    step = extent / 4
    reach = np.linalg.norm(np.ptp(asm.bounds, axis=0)) * 2
    for k in range(1, int(reach / step) + 2):
        moved = mover.translate(list(k * step * np.asarray(direction)))
        if (moved ^ others).volume() > threshold:
            return False
    return True


@pytest.mark.parametrize(("n", "seed"), [(20, 1), (35, 2), (50, 3)])
def test_box_packings_plans_and_queries_agree(n, seed):
    asm = guillotine_packing(n, seed)
    tol = asm.tolerance()
    result = plan(asm, max_and_or_parts=0)
    assert result.feasible == separable_by_translations(asm)
    assert result.feasible  # guillotine cuts come apart
    members = set(asm.names)
    for number, step in enumerate(result.steps):
        rest = [p for p in members if p not in step.parts]
        dbg = extended_dbg(asm, step.direction, tuple(sorted(members)), tol)
        assert not any(i in step.parts and j in rest for i, j in dbg.arcs)
        if number == 0:
            for name in step.parts:
                found = can_extract(asm, [name])
                assert found is not None
                assert all(extended_free(asm, [name], d, tol) for d in found.directions)
        area = min(asm.parts[p].mesh.area for p in step.parts)
        assert swept_free(asm, step.parts, rest, step.direction, 1e-6 * area), step
        members -= set(step.parts)
