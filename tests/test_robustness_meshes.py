"""Mesh answers under vertex noise and scaling: contacts, motion kinds and plans.

Every vertex of a bundled assembly is moved by seeded uniform noise of amplitude
``level`` x the model's size along each axis. At 1e-8 (a hundredth of the default mesh
tolerance) the default policy must give the same contact pairs, motion kinds and plan as
the exact meshes; at 1e-6 (the default tolerance itself) the same answers come with a
tolerance five times the noise (``--tolerance 5e-6``, docs/geometry.md). Scaling the
whole model by 1e-3 or 1e3 changes no answer (every threshold is relative to its size).
The hand-known answers: the hinge's door turns about its pin (revolute), the gearbox's
cover is fixed and its gears turn, the stacked blocks slide on each other (planar).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

import assemblykit
from assemblykit.geometry.contacts import assembly_contacts
from assemblykit.geometry.precision import combined, coordinate_precision
from assemblykit.io.assembly import load_assembly
from assemblykit.model.assembly import Assembly, Part
from assemblykit.tolerance import Tolerance
from datasets import dataset, shared_assembly

EXAMPLES = Path(assemblykit.__file__).parent / "examples"
MATCHING = Tolerance.relative(5e-6)
"""The tolerance matching 1e-6 noise: five times its amplitude."""


def _changed(asm: Assembly, level: float = 0.0, factor: float = 1.0, seed: int = 7) -> Assembly:
    """``asm`` scaled by ``factor`` about the origin, each vertex then moved by seeded
    uniform noise of amplitude ``level`` x its scaled size per axis; the precision the
    loader measured is kept (with the noisy coordinates' own)."""
    rng = np.random.default_rng(seed)
    size = asm.scale * factor
    parts = []
    for part in asm.parts.values():
        mesh = part.mesh.copy()
        vertices = np.asarray(mesh.vertices, dtype=np.float64) * factor
        mesh.vertices = vertices + rng.uniform(-1.0, 1.0, vertices.shape) * level * size
        parts.append(Part(part.name, mesh, part.pose, source=part.source))
    measured = [coordinate_precision(p.mesh.vertices) for p in parts]
    if asm.precision is not None and factor == 1.0:
        measured.append(asm.precision)
    return Assembly(parts, units=asm.units, source=asm.source, precision=combined(measured))


def _contacts(asm: Assembly, tol: Tolerance | None = None) -> dict[tuple[str, str], str]:
    """Per touching pair, which kinds of patches it has (``planar``, ``curved``, both)."""
    return {
        c.pair: "+".join(k for k, n in (("planar", c.planar), ("curved", c.curved)) if n)
        for c in assembly_contacts(asm, tol)
    }


def _kinds(asm: Assembly, tol: Tolerance | None = None) -> dict[str, str]:
    parts = assemblykit.motion(asm, tol=tol).to_dict()["parts"]
    return {name: entry["motion"] for name, entry in parts.items()}


def _plan(asm: Assembly, tol: Tolerance | None = None) -> tuple[bool, list[Any]]:
    data = assemblykit.plan(asm, tol=tol).to_dict()
    return data["feasible"], [sorted(step["parts"]) for step in data["steps"]]


@pytest.fixture(scope="module")
def hinge() -> Assembly:
    return load_assembly(EXAMPLES / "motion" / "hinge" / "hinge.yaml")


@pytest.fixture(scope="module")
def gearbox() -> Assembly:
    return load_assembly(EXAMPLES / "motion" / "gearbox" / "gearbox.yaml")


@pytest.fixture(scope="module")
def demo() -> Assembly:
    return load_assembly(EXAMPLES / "gearbox_demo" / "gearbox.yaml")


@pytest.fixture(scope="module")
def stack() -> Assembly:
    return load_assembly(dataset("compas_assembly/stack_assembly.json"))


HINGE = {("frame", "door"): "planar+curved"}
GEARBOX_KINDS = {"housing": "fixed", "cover": "fixed"} | {
    f"gear_{k}": "revolute" for k in range(1, 5)
}


@pytest.mark.parametrize(("level", "tol"), [(1e-8, None), (1e-6, MATCHING)])
def test_the_hinge_keeps_its_thrust_face_and_turns(hinge, level, tol):
    noisy = _changed(hinge, level)
    assert _contacts(noisy, tol) == HINGE
    assert _kinds(noisy, tol) == {"frame": "revolute", "door": "revolute"}


@pytest.mark.parametrize(("level", "tol"), [(1e-8, None), (1e-6, MATCHING)])
def test_the_gearbox_cover_stays_fixed_and_its_gears_turn(gearbox, level, tol):
    noisy = _changed(gearbox, level)
    assert _contacts(noisy, tol) == _contacts(gearbox)
    assert _kinds(noisy, tol) == GEARBOX_KINDS


@pytest.mark.parametrize(("level", "tol"), [(1e-8, None), (1e-6, MATCHING)])
def test_the_stacked_blocks_keep_every_joint(stack, level, tol):
    noisy = _changed(stack, level)
    joints = {(str(k), str(k + 1)): "planar" for k in range(9)}
    assert _contacts(noisy, tol) == joints
    # each block slides on the ones it rests on (and the top one on its only joint)
    assert set(_kinds(noisy, tol).values()) == {"planar"}


@pytest.mark.parametrize(
    ("level", "tol"), [pytest.param(1e-8, None, marks=pytest.mark.slow), (1e-6, MATCHING)]
)
def test_the_demo_gearbox_keeps_contacts_motions_and_plan(demo, level, tol):
    noisy = _changed(demo, level)
    assert _contacts(noisy, tol) == _contacts(demo)
    kinds = _kinds(noisy, tol)
    assert kinds == _kinds(demo)
    assert kinds["cover"] == "fixed" and kinds["gear_a"] == "revolute"
    feasible, steps = _plan(noisy, tol)
    if level == 1e-8:
        assert (feasible, steps) == _plan(demo)
    else:
        # the same parts come out, all but the base; which of several equally good
        # removals goes first may change with directions a noise's width off the axes
        assert feasible
        assert sorted(p for s in steps for p in s) == sorted(set(demo.names) - {"base"})


@pytest.mark.parametrize("name", ["arch_assembly.json"])
def test_the_arch_keeps_every_joint_under_noise(name):
    arch = load_assembly(dataset(f"compas_assembly/{name}"))
    assert _contacts(_changed(arch, 1e-8)) == _contacts(arch)


def test_the_beam_keeps_its_joints_and_stays_fixed_under_noise():
    # the five pieces of ASAP's beam interlock through four planar joints
    noisy = _changed(shared_assembly("asap_beam_assembly"), 1e-8)
    joints = [("0", "2"), ("1", "3"), ("2", "6"), ("3", "6")]
    assert _contacts(noisy) == dict.fromkeys(joints, "planar")
    assert set(_kinds(noisy).values()) == {"fixed"}


# metres read as mm in the default tier; mm read as metres too in the slow one
UNITS = [1e-3, pytest.param(1e3, marks=pytest.mark.slow)]


@pytest.mark.parametrize("factor", UNITS)
def test_answers_do_not_depend_on_the_unit(hinge, gearbox, factor):
    for asm in (hinge, gearbox):
        scaled = _changed(asm, factor=factor)
        assert _contacts(scaled) == _contacts(asm)
        assert _kinds(scaled) == _kinds(asm)
    assert _plan(_changed(hinge, factor=factor))[0] == _plan(hinge)[0]


@pytest.mark.parametrize("factor", UNITS)
def test_the_demo_plan_does_not_depend_on_the_unit(demo, factor):
    assert _plan(_changed(demo, factor=factor)) == _plan(demo)
