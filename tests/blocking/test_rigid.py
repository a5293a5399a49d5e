"""Γ_g: infinitesimal rigid motions decided by linear programming (seed 004, Fig. 5)."""

from __future__ import annotations

import numpy as np
from blocking_helpers import ContactAssembly, square

from assemblykit.blocking.ndbg import blocking_graph
from assemblykit.geometry.contacts import Contact


def wedged_block() -> ContactAssembly:
    """A unit block (x, z in [0, 1]) held by small patches: floor near x = 0.5, ceiling
    near x = 0.9, left wall near z = 0.9, right wall near z = 0.1, and the two y walls.
    Every translation is blocked; a rotation about y through (0.7, 0.5) frees it."""
    h = 0.05
    patches = (
        square([0, 0, -1], (0.5, 0.5, 0.0), h),
        square([0, 0, 1], (0.9, 0.5, 1.0), h),
        square([-1, 0, 0], (0.0, 0.5, 0.9), h),
        square([1, 0, 0], (1.0, 0.5, 0.1), h),
        square([0, 1, 0], (0.5, 1.0, 0.5), 0.4),
        square([0, -1, 0], (0.5, 0.0, 0.5), 0.4),
    )
    return ContactAssembly(["block", "frame"], [Contact("block", "frame", planar=patches)])


def test_rotation_frees_what_translation_cannot():
    asm = wedged_block()
    translations = blocking_graph(asm, "infinitesimal")
    assert frozenset({"block"}) not in {r.parts for r in translations.removable()}
    rigid = blocking_graph(asm, "rigid")
    removal = {r.parts: r for r in rigid.removable()}[frozenset({"block"})]
    (twist,) = removal.directions
    omega, v = twist[:3], twist[3:]
    assert abs(np.linalg.norm(twist) - 1) < 1e-12
    assert np.linalg.norm(omega) > 0.1
    assert abs(omega[0]) < 1e-9 and abs(omega[2]) < 1e-9  # about the y axis
    # the twist moves every contact point of the block outward or tangentially
    pts, normals = rigid.constraints({"block"})
    speeds = np.einsum("ij,ij->i", normals, v + np.cross(omega, pts))
    assert np.all(speeds <= 1e-9) and np.any(speeds < -1e-6)
    assert rigid.dbg(twist).is_free({"block"})


def test_rotation_is_blocked_with_a_full_floor_and_ceiling():
    asm = wedged_block()
    contact = asm.given[0]
    full = Contact(
        "block",
        "frame",
        planar=(
            *contact.planar,
            square([0, 0, -1], (0.5, 0.5, 0.0), 0.45),
            square([0, 0, 1], (0.5, 0.5, 1.0), 0.45),
        ),
    )
    rigid = blocking_graph(ContactAssembly(["block", "frame"], [full]), "rigid")
    assert rigid.free_twist({"block"}) is None
    assert rigid.removable() == []
    assert rigid.to_dict()["removable"] == []
