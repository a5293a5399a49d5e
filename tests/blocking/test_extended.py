"""Γ_e: blocking for extended translations (seed 004, "Extended translations")."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import trimesh
from blocking_helpers import box, mesh_assembly

from assemblykit.blocking.extended import extended_dbg, extended_free, obstacles
from assemblykit.blocking.ndbg import blocking_graph
from assemblykit.blocking.queries import can_extract, removable_parts
from assemblykit.io.assembly import load_assembly
from datasets import dataset


def ring(center, plane: str) -> trimesh.Trimesh:
    """A square ring of four bars (convex pieces): outer half-size 1.5, bar width 0.5,
    thickness 0.5, in the plane 'xy' or 'xz' around ``center``."""
    c = np.asarray(center, dtype=float)
    bars = []
    for lo, hi in (
        ([-1.5, -1.5], [-1.0, 1.5]),
        ([1.0, -1.5], [1.5, 1.5]),
        ([-1.0, -1.5], [1.0, -1.0]),
        ([-1.0, 1.0], [1.0, 1.5]),
    ):
        if plane == "xy":
            bars.append(
                box(c + np.array([lo[0], lo[1], -0.25]), c + np.array([hi[0], hi[1], 0.25]))
            )
        else:
            bars.append(
                box(c + np.array([lo[0], -0.25, lo[1]]), c + np.array([hi[0], 0.25, hi[1]]))
            )
    return trimesh.util.concatenate(bars)


def test_locally_free_but_blocked_farther_along():
    asm = mesh_assembly(
        {
            "table": box([-2, -2, -1], [2, 2, 0]),
            "block": box([0, 0, 0], [1, 1, 1]),
            "lamp": box([0, 0, 3], [1, 1, 4]),  # hangs above the block, not touching it
        }
    )
    up = np.array([0.0, 0.0, 1.0])
    local = blocking_graph(asm, "infinitesimal")
    assert local.dbg(up).is_free({"block"})
    extended = blocking_graph(asm, "extended")
    assert not extended.dbg(up).is_free({"block"})
    assert extended.dbg(up).blocks("lamp", "block")
    assert extended_dbg(asm, up, tuple(asm.names), asm.tolerance()).arcs == extended.dbg(up).arcs
    sideways = extended.dbg([1.0, 0.0, 0.0])
    assert sideways.is_free({"block"})
    for region in extended.regions():
        assert region.dbg.arcs == extended.dbg(region.direction).arcs


def post_on_plate(layer: float) -> object:
    """A 1 x 1 x 10 post standing on a 10 x 10 x 1 plate, sunk ``layer`` into it."""
    return mesh_assembly(
        {"plate": box([-5, -5, -1], [5, 5, 0]), "post": box([0, 0, -layer], [1, 1, 10 - layer])}
    )


def test_a_layer_thinner_than_the_interference_policy_is_a_contact():
    probe = post_on_plate(0.0)
    tol = probe.tolerance()
    # thicker than the length tolerance (the cones alone would block every direction),
    # thinner than what the policy calls interference (tolerance x the post's area 42)
    layer = 5 * tol.length
    asm = post_on_plate(layer)
    for direction in ([0, 0, 1], [1, 0, 0], [0, 1, 1]):
        assert extended_free(asm, ["post"], direction, tol)
    assert not extended_free(asm, ["post"], [0, 0, -1], tol)
    assert not extended_free(asm, ["post"], [1, 0, -1], tol)
    # the post is tested backed out of the plate by the layer, straight up
    np.testing.assert_allclose(obstacles(asm).backout("post", "plate", tol), [0, 0, layer])
    # a real interference stays an obstacle in every direction
    deep = post_on_plate(0.1)
    assert not any(extended_free(deep, ["post"], d, tol) for d in ([0, 0, 1], [1, 0, 0], [0, 1, 1]))


def test_interlocked_rings_have_no_removable_subassembly():
    asm = mesh_assembly({"r1": ring([0, 0, 0], "xy"), "r2": ring([1.25, 0, 0], "xz")})
    assert asm.contacts() == []
    g = blocking_graph(asm, "extended")
    assert g.removable() == []
    # without the interlock (second ring moved away) they separate
    apart = mesh_assembly({"r1": ring([0, 0, 0], "xy"), "r2": ring([5, 0, 0], "xz")})
    assert blocking_graph(apart, "extended").removable() != []


ROOT = Path(__file__).resolve().parents[2]
DEMO = ROOT / "src" / "assemblykit" / "examples" / "gearbox_demo" / "gearbox.yaml"


@pytest.mark.slow
def test_gearbox_pins_and_cover_lift_out_exactly():
    asm = load_assembly(DEMO)
    tol = asm.tolerance()
    up = np.array([0.0, 0.0, 1.0])
    g = blocking_graph(asm, "extended")
    # the housing is not convex: Γ_e is exact at each region of Γ_t
    assert g.exact is not None
    dbg = g.dbg(up)
    for pin in ("pin_1", "pin_2", "pin_3", "pin_4"):
        assert not any(i == pin for i, _ in dbg.arcs), pin
        # sideways the pin runs into the cover's bore
        assert not extended_free(asm, [pin], [1.0, 0.0, 0.0], tol)
        found = can_extract(asm, [pin])
        assert found is not None and any(np.allclose(d, up) for d in found.directions)
    assert can_extract(asm, ["gear_a"]) is None  # inside the closed housing
    for region in g.regions()[:5]:
        assert region.dbg.arcs == extended_dbg(asm, region.direction, g.parts, tol).arcs


def test_asap_beam_parts_are_removable_along_exact_directions():
    asm = load_assembly(dataset("asap_beam_assembly"))
    tol = asm.tolerance()
    removals = removable_parts(asm)
    assert removals, "some beam part comes out by one translation"
    for removal in removals:
        for d in removal.directions[:2]:
            assert extended_free(asm, removal.parts, d, tol)
