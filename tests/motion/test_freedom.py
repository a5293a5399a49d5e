"""Motion of parts and subassemblies (Liu 1997 eq. (2)) on the bundled motion examples."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import trimesh

import assemblykit
from assemblykit.algebra import se3
from assemblykit.errors import UnknownNameError
from assemblykit.features import compound_group
from assemblykit.features.primitives import Plane
from assemblykit.io.assembly import load_assembly
from assemblykit.model.assembly import Assembly, Part
from assemblykit.motion.freedom import MotionReport, motion, part_motion
from assemblykit.motion.separation import contact_graph, separable_subassemblies
from assemblykit.tolerance import Tolerance

EXAMPLES = Path(assemblykit.__file__).parent / "examples" / "motion"
GEAR_X = {"gear_1": 0.0, "gear_2": 30.0, "gear_3": 55.0, "gear_4": 85.0}


def example(name: str, suffix: str = "yaml") -> Path:
    return EXAMPLES / name / f"{name}.{suffix}"


@pytest.fixture(scope="module")
def reports() -> dict[str, MotionReport]:
    names = ("hinge", "drawer", "ball_joint", "gearbox", "interlock")
    return {name: motion(load_assembly(example(name))) for name in names}


def _axis(data: dict) -> tuple[np.ndarray, np.ndarray]:
    return np.array(data["axis"]["point"]), np.array(data["axis"]["direction"])


def test_hinge_door_turns_about_the_pin(reports: dict[str, MotionReport]) -> None:
    door = reports["hinge"]["door"].to_dict()
    assert (door["motion"], door["dof"], door["components"]) == ("revolute", 1, 1)
    point, direction = _axis(door)
    np.testing.assert_allclose(point, [0.0, 0.0, 0.0], atol=1e-6)
    np.testing.assert_allclose(direction, [0.0, 0.0, 1.0], atol=1e-6)
    # the knuckle only rests on the frame: it lifts off straight up the pin
    np.testing.assert_allclose(door["unilateral"]["lift_off"], [[0.0, 0.0, 1.0]], atol=1e-6)
    assert door["touching"] == ["frame"]


def test_drawer_slides_along_its_runners(reports: dict[str, MotionReport]) -> None:
    tray = reports["drawer"]["tray"].to_dict()
    assert (tray["motion"], tray["dof"]) == ("prismatic", 1)
    np.testing.assert_allclose(tray["direction"], [1.0, 0.0, 0.0], atol=1e-9)
    # the two walls are swapped by the half-turn about a vertical line (Liu 1997 Prop 3.2.8)
    assert tray["components"] == 2
    np.testing.assert_allclose(tray["unilateral"]["lift_off"], [[0.0, 0.0, 1.0]], atol=1e-9)
    sliding = np.array(tray["unilateral"]["sliding"])
    np.testing.assert_allclose(np.abs(sliding), [[1.0, 0.0, 0.0]], atol=1e-9)


def test_ball_turns_about_its_centre_and_lifts_out_of_the_cup(
    reports: dict[str, MotionReport],
) -> None:
    ball = reports["ball_joint"]["ball"].to_dict()
    assert (ball["motion"], ball["dof"]) == ("spherical", 3)
    np.testing.assert_allclose(ball["center"], [0.0, 0.0, 0.0], atol=1e-6)
    # the cup is less than a hemisphere: every upward direction frees the ball, the
    # pointed cone of lift-off directions has +z inside it
    rays = np.array(ball["unilateral"]["lift_off"])
    assert len(rays) >= 3 and np.all(rays[:, 2] > 0)
    assert ball["unilateral"]["sliding"] == []


def test_gearbox_gears_turn_on_their_pins_cover_and_housing_are_fixed(
    reports: dict[str, MotionReport],
) -> None:
    report = reports["gearbox"]
    for gear, x in GEAR_X.items():
        data = report[gear].to_dict()
        assert (data["motion"], data["dof"], data["components"]) == ("revolute", 1, 1)
        point, direction = _axis(data)
        np.testing.assert_allclose(point, [x, 0.0, 0.0], atol=1e-6)
        np.testing.assert_allclose(direction, [0.0, 0.0, 1.0], atol=1e-9)
        np.testing.assert_allclose(data["unilateral"]["lift_off"], [[0.0, 0.0, 1.0]], atol=1e-6)
    for fixed in ("cover", "housing"):
        assert (report[fixed].kind, report[fixed].dof) == ("fixed", 0)
    # bilaterally the pinned cover is fixed; pushing only, it lifts off the walls
    np.testing.assert_allclose(
        report["cover"].to_dict()["unilateral"]["lift_off"], [[0.0, 0.0, 1.0]], atol=1e-6
    )
    assert report["housing"].touching == ("cover", *GEAR_X)


def test_interlock_parts_are_all_fixed_alone(reports: dict[str, MotionReport]) -> None:
    report = reports["interlock"]
    for name in ("bar_a", "bar_b", "base", "lid"):
        assert (report[name].kind, report[name].dof) == ("fixed", 0)
    # pushing only, the enclosed bars are held; the lid lifts off up, the base down
    assert not report["bar_a"].unilateral.free and not report["bar_b"].unilateral.free
    np.testing.assert_allclose(report["lid"].unilateral.lift_off, [[0.0, 0.0, 1.0]], atol=1e-9)
    np.testing.assert_allclose(report["base"].unilateral.lift_off, [[0.0, 0.0, -1.0]], atol=1e-9)
    # no continuous motion, but two equivalent positions (Liu 1997 eq. (2), a finite
    # group): bar_a's seven contact planes (normals +-x, +-y, -z and two +z) are mapped
    # onto themselves by the half-turn about the vertical line x = 1.5, y = 2
    group = report["bar_a"].group
    assert group is not None and group.n_components == 2
    half_turn = (
        se3.translation([1.5, 2.0, 0.0]) @ se3.rot_z(np.pi) @ se3.translation([-1.5, -2.0, 0.0])
    )
    assert group.contains(half_turn)
    assert not group.contains(se3.rot_z(np.pi))


def test_interlock_pair_slides_out_along_x() -> None:
    assembly = load_assembly(example("interlock"))
    pair = part_motion(assembly, ["bar_a", "bar_b"])
    data = pair.to_dict()
    assert pair.key == "bar_a+bar_b"
    assert (data["motion"], data["dof"]) == ("prismatic", 1)
    np.testing.assert_allclose(data["direction"], [1.0, 0.0, 0.0], atol=1e-9)
    assert data["unilateral"]["lift_off"] == []
    assert data["unilateral"]["free"]


def test_separation_finds_the_pair_of_seed_003_fig_10() -> None:
    assembly = load_assembly(example("interlock"))
    graph = contact_graph(assembly)
    assert sorted(map(sorted, graph.edges)) == [
        ["bar_a", "bar_b"],
        ["bar_a", "base"],
        ["bar_b", "base"],
        ["bar_b", "lid"],
        ["base", "lid"],
    ]
    found = separable_subassemblies(assembly)
    assert [m.parts for m in found] == [("bar_a", "bar_b")]
    assert found[0].kind == "prismatic"
    assert separable_subassemblies(assembly, max_size=1) == []


def test_subassemblies_are_keyed_by_their_parts() -> None:
    assembly = load_assembly(example("interlock"))
    report = motion(assembly, subassemblies=[["base", "lid"]])
    assert list(report.to_dict()["parts"]) == ["bar_a", "bar_b", "base", "lid", "base+lid"]
    # the rest of the pair slides the other way along the same line
    assert report["base+lid"].kind == "prismatic"


def test_unknown_part_names_the_part() -> None:
    assembly = load_assembly(example("hinge"))
    with pytest.raises(UnknownNameError, match="nope"):
        part_motion(assembly, ["door", "nope"])


def _box(name: str, lo: tuple[float, float, float], hi: tuple[float, float, float]) -> Part:
    extents = np.subtract(hi, lo)
    mesh = trimesh.creation.box(extents=extents)
    mesh.apply_translation(np.add(lo, hi) / 2.0)
    return Part(name, mesh)


def test_block_on_a_table_is_planar_and_lifts_off_into_the_upper_hemisphere() -> None:
    table = _box("table", (-5.0, -5.0, -1.0), (5.0, 5.0, 0.0))
    block = _box("block", (-1.0, -1.0, 0.0), (1.0, 1.0, 2.0))
    moved = part_motion(Assembly([table, block]), "block").to_dict()
    assert (moved["motion"], moved["dof"], moved["components"]) == ("planar", 3, 1)
    np.testing.assert_allclose(moved["normal"], [0.0, 0.0, 1.0], atol=1e-12)
    reading = moved["unilateral"]
    np.testing.assert_allclose(reading["lift_off"], [[0.0, 0.0, 1.0]], atol=1e-12)
    sliding = np.array(reading["sliding"])
    np.testing.assert_allclose(sliding.T @ sliding, np.diag([1.0, 1.0, 0.0]), atol=1e-12)


def test_a_part_touching_nothing_is_free() -> None:
    alone = _box("alone", (0.0, 0.0, 0.0), (1.0, 1.0, 1.0))
    other = _box("other", (3.0, 0.0, 0.0), (4.0, 1.0, 1.0))
    moved = part_motion(Assembly([alone, other]), "alone")
    assert (moved.kind, moved.dof, moved.group, moved.touching) == ("free", 6, None, ())
    assert moved.unilateral.free and moved.unilateral.lift_off == ()


STEP_MODELS = ("hinge", "drawer", "ball_joint", "gearbox", "interlock")


@pytest.mark.cad
@pytest.mark.slow
@pytest.mark.parametrize("name", STEP_MODELS)
def test_step_and_mesh_input_give_the_same_motions(
    name: str, reports: dict[str, MotionReport]
) -> None:
    pytest.importorskip("OCP")
    pytest.importorskip("assemblykit.io.step")
    exact = motion(load_assembly(example(name, "step")))
    meshed = reports[name]
    # the STEP reader names the parts after the file's products (the manifest's names)
    assert list(exact.motions) == list(meshed.motions)
    for key, moved in exact.motions.items():
        assert (moved.kind, moved.dof) == (meshed[key].kind, meshed[key].dof), key


@pytest.mark.cad
def test_step_gearbox_axes_are_exact() -> None:
    pytest.importorskip("OCP")
    pytest.importorskip("assemblykit.io.step")
    assembly = load_assembly(example("gearbox", "step"))
    report = motion(assembly)
    limit = 1e-9 * assembly.scale
    for name, x in GEAR_X.items():
        point, direction = _axis(report[name].to_dict())
        assert np.max(np.abs(point - [x, 0.0, 0.0])) <= limit
        assert np.max(np.abs(direction - [0.0, 0.0, 1.0])) <= 1e-9


def test_public_api_stays_callable_after_the_package_is_imported() -> None:
    assembly = load_assembly(example("hinge"))
    first = assemblykit.motion(assembly)
    second = assemblykit.motion(assembly)
    assert first["door"].kind == second["door"].kind == "revolute"


def test_a_cube_boxed_in_on_six_sides_has_the_24_rotations_of_the_cube() -> None:
    faces = [Plane(point=s * axis, normal=s * axis) for axis in np.eye(3) for s in (1.0, -1.0)]
    group = compound_group(faces, Tolerance().with_scale(4.0))
    assert (group.dof, group.n_components) == (0, 24)
    half_turn_x = np.diag([1.0, -1.0, -1.0, 1.0])
    quarter_turn_z = se3.rot_z(np.pi / 2)
    assert group.contains(half_turn_x) and group.contains(quarter_turn_z @ half_turn_x)
    assert not group.contains(se3.translation((0.5, 0.0, 0.0)))


def test_a_rod_in_a_half_round_groove_slides_along_it_and_lifts_off_upwards() -> None:
    from curved_parts import rod_in_groove

    rod = part_motion(rod_in_groove(through=True), "rod")
    # the fit of Liu 1997 keeps the shaft: turning about and sliding along y
    assert rod.kind == "cylindrical"
    reading = rod.unilateral
    # the groove pushes only along its half circle of normals -x, -z, +x: the free
    # translations are d_x = 0, d_z >= 0, i.e. sliding along y and lifting off along +z
    (sliding,) = reading.sliding
    np.testing.assert_allclose(np.abs(sliding), [0.0, 1.0, 0.0], atol=1e-6)
    (lift,) = reading.lift_off
    np.testing.assert_allclose(lift, [0.0, 0.0, 1.0], atol=1e-6)


def test_a_rod_in_a_closed_groove_turns_in_it_and_lifts_off_only_upwards() -> None:
    from curved_parts import rod_in_groove

    rod = part_motion(rod_in_groove(through=False), "rod")
    assert rod.kind == "revolute"
    assert rod.unilateral.sliding == ()
    (lift,) = rod.unilateral.lift_off
    np.testing.assert_allclose(lift, [0.0, 0.0, 1.0], atol=1e-6)
    np.testing.assert_allclose(rod.unilateral.witness, [0, 0, 0, 0, 0, 1], atol=1e-6)
