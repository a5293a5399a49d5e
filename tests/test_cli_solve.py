"""``assemblykit solve``: answers on the bundled examples, one line and exit 2 on bad input."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

import assemblykit
from assemblykit.cli import main

try:
    import assemblykit.inference
except ImportError as missing:  # the engine is a separate layer; only its answers need it
    ENGINE = f"the inference engine cannot be imported: {missing}"
else:
    ENGINE = ""

needs_engine = pytest.mark.skipif(bool(ENGINE), reason=ENGINE or "engine present")

EXAMPLES = Path(assemblykit.__file__).parent / "examples" / "tasks"

GOOD = """\
units mm
body table fixed
  plane top point (0,0,0) normal (0,0,1)
end
body block
  plane bottom point (0,0,0) normal (0,0,-1)
  hole bore point (5,5,10) axis (0,0,-1) radius 2
  ball knob point (0,0,0) radius 1
end
body peg
  shaft shaft point (0,0,0) axis (0,0,1) radius 2
end
situation s1
  against bottom of block, top of table
  fits shaft of peg, bore of block
end
situation s2
  move block parallel bore of block by 5
end
"""

BAD = {
    "unknown feature type": (".rapt", GOOD.replace("shaft shaft", "shafts shaft"), "line 11"),
    "zero normal": (".rapt", GOOD.replace("normal (0,0,1)", "normal (0,0,0)"), "line 3"),
    "negative radius": (
        ".rapt",
        GOOD.replace("radius 2\nend\nsit", "radius -2\nend\nsit"),
        "line 11",
    ),
    "against plane-shaft": (".rapt", GOOD.replace("top of table", "shaft of peg"), "line 14"),
    "missing feature": (".rapt", GOOD.replace("bore of block\n", "bor of block\n"), "line 15"),
    "unknown body": (".rapt", GOOD.replace("of block,", "of blok,"), "line 14"),
    "duplicate names": (".rapt", GOOD.replace("body peg", "body block"), "line 10"),
    "move along no axis": (
        ".rapt",
        GOOD.replace("bore of block by", "knob of block by"),
        "line 18",
    ),
    "rapt syntax": (".rapt", GOOD.replace("(5,5,10)", "(5,5 10)"), "line 7, column 24"),
    "malformed yaml": (".yaml", "units: mm\nbodies: {a: [1, 2}\n", "line 2"),
    "unknown relation": (
        ".yaml",
        "bodies: {a: {fixed: true}}\nsituations: [{name: s, relations: [[agains, a.x, a.y]]}]\n",
        "situations[0].relations[0]",
    ),
}


def run(args: list[str]) -> int:
    try:
        main(args)
    except SystemExit as done:
        return int(done.code or 0)
    return 0


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_input_exits_2_with_one_line_naming_file_and_place(
    case: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
):
    suffix, text, place = BAD[case]
    path = tmp_path / f"task{suffix}"
    path.write_text(text)
    assert run(["solve", str(path)]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    lines = captured.err.splitlines()
    assert len(lines) == 1, captured.err
    assert lines[0].startswith(f"assemblykit: task{suffix}: ")
    assert place in lines[0]


def test_a_missing_file_exits_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]):
    assert run(["solve", str(tmp_path / "absent.rapt")]) == 2
    assert len(capsys.readouterr().err.splitlines()) == 1


def solve_json(name: str, capsys: pytest.CaptureFixture[str], *extra: str) -> dict:
    assert run(["solve", str(EXAMPLES / name), "--json", *extra]) == 0
    out = json.loads(capsys.readouterr().out)
    assert set(out) >= {"status", "bodies", "conflicts"}
    for key, body in out["bodies"].items():
        assert "@" in key
        assert set(body) >= {"pose", "dof", "motion", "invariants"}
        assert np.asarray(body["pose"]).shape == (4, 4)
    return out


def underconstrained_bodies(name: str, capsys: pytest.CaptureFixture[str]) -> dict:
    """The bodies of an example solved as underconstrained without conflicts."""
    out = solve_json(name, capsys)
    assert out["status"] == "underconstrained" and out["conflicts"] == []
    return out["bodies"]


def translation(body: dict) -> np.ndarray:
    return np.asarray(body["pose"])[:3, 3]


@needs_engine
@pytest.mark.parametrize("suffix", [".yaml", ".rapt"])
def test_peg_in_block_is_cylindrical_then_revolute(suffix: str, capsys):
    bodies = underconstrained_bodies(f"peg_in_block{suffix}", capsys)
    assert (bodies["block@s1"]["dof"], bodies["block@s1"]["motion"]) == (0, "fixed")
    np.testing.assert_allclose(bodies["block@s1"]["pose"], np.eye(4), atol=1e-9)
    assert (bodies["peg@s1"]["dof"], bodies["peg@s1"]["motion"]) == (2, "cylindrical")
    assert (bodies["peg@s2"]["dof"], bodies["peg@s2"]["motion"]) == (1, "revolute")
    np.testing.assert_allclose(translation(bodies["peg@s2"]), [5, 5, 10], atol=1e-9)


ONE_DOF = {
    "w2_slide": {"cube@s1": (1, "prismatic")},
    "w4_pin": {"pin@s1": (1, "revolute")},
    "triangle": {"a@s1": (1, "prismatic"), "b@s1": (1, "prismatic")},
}


@needs_engine
@pytest.mark.parametrize("name", sorted(ONE_DOF))
def test_one_dof_examples(name: str, capsys):
    out = solve_json(f"{name}.yaml", capsys)
    assert out["status"] == "underconstrained"
    for body, (dof, motion) in ONE_DOF[name].items():
        assert (out["bodies"][body]["dof"], out["bodies"][body]["motion"]) == (dof, motion)


@needs_engine
def test_four_bar_is_a_one_dof_mechanism(capsys):
    bodies = underconstrained_bodies("four_bar.rapt", capsys)
    assert (bodies["crank@s1"]["dof"], bodies["crank@s1"]["motion"]) == (1, "revolute")
    assert (bodies["rocker@s1"]["dof"], bodies["rocker@s1"]["motion"]) == (1, "revolute")
    assert (bodies["coupler@s1"]["dof"], bodies["coupler@s1"]["motion"]) == (1, "mechanism")
    np.testing.assert_allclose(bodies["crank@s1"]["invariants"]["point"][:2], [0, 0], atol=1e-9)
    np.testing.assert_allclose(bodies["rocker@s1"]["invariants"]["point"][:2], [40, 0], atol=1e-9)


@needs_engine
def test_four_bar_yaml_closes_where_it_is_drawn(capsys):
    """The four-bar is drawn closed: every body stays at its pose as written, the crank
    turning about A = (0, 0) and the rocker about D = (40, 0)."""
    bodies = underconstrained_bodies("four_bar.yaml", capsys)
    for body in bodies.values():
        np.testing.assert_allclose(body["pose"], np.eye(4), atol=1e-9)
    assert (bodies["coupler@s1"]["dof"], bodies["coupler@s1"]["motion"]) == (1, "mechanism")
    np.testing.assert_allclose(bodies["crank@s1"]["invariants"]["point"][:2], [0, 0], atol=1e-9)
    np.testing.assert_allclose(bodies["rocker@s1"]["invariants"]["point"][:2], [40, 0], atol=1e-9)


@needs_engine
def test_four_bar_out_of_reach_is_inconsistent_by_how_far_it_stays_open(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
):
    """The ground pivot D and the rocker moved to x = 100: crank 10, coupler √1700 and
    rocker 20 reach 71.23 of the 100 between the pivots, so the loop stays open by
    100 - 10 - √1700 - 20 ≈ 28.77, reported without a numeric search."""
    text = (EXAMPLES / "four_bar.yaml").read_text()
    for old, new in (
        ("pin_d: {type: shaft, point: [40, 0, 0]", "pin_d: {type: shaft, point: [100, 0, 0]"),
        ("hole_d: {type: hole, point: [40, 0, 0]", "hole_d: {type: hole, point: [100, 0, 0]"),
        ("pin_c:  {type: shaft, point: [40, 20, 1]", "pin_c:  {type: shaft, point: [100, 20, 1]"),
    ):
        assert text.count(old) == 1
        text = text.replace(old, new)
    path = tmp_path / "far_four_bar.yaml"
    path.write_text(text)
    assert run(["solve", str(path), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["status"] == "inconsistent"
    (conflict,) = out["conflicts"]
    assert conflict["kind"] == "loop"
    assert conflict["value"] == pytest.approx(100 - 10 - math.sqrt(1700) - 20, abs=1e-9)
    assert "cannot close" in conflict["message"]


@needs_engine
def test_slide_direction_and_triangle_offset(capsys):
    cube = solve_json("w2_slide.rapt", capsys)["bodies"]["cube@s1"]
    direction = np.asarray(cube["invariants"]["direction"])
    np.testing.assert_allclose(np.abs(direction), [0, 1, 0], atol=1e-9)
    b = solve_json("triangle.rapt", capsys)["bodies"]["b@s1"]
    assert translation(b)[0] == pytest.approx(1.0, abs=1e-9)
    assert translation(b)[2] == pytest.approx(0.0, abs=1e-9)


@needs_engine
def test_square_peg_has_four_poses(capsys):
    out = solve_json("w14_square_peg.rapt", capsys)
    peg = out["bodies"]["peg@s1"]
    assert out["status"] == "ambiguous"
    assert (peg["dof"], peg["solutions"]) == (0, 4)


@needs_engine
def test_unequal_pins_are_inconsistent_by_2(capsys):
    out = solve_json("w6_unequal_pins.rapt", capsys)
    assert out["status"] == "inconsistent"
    (conflict,) = out["conflicts"]
    assert conflict["kind"] == "distance"
    assert conflict["value"] == pytest.approx(2.0, abs=1e-9)


@needs_engine
def test_actions_lift_then_turn_the_plate(capsys):
    bodies = solve_json("stack_and_move.rapt", capsys)["bodies"]
    np.testing.assert_allclose(bodies["plate@stacked"]["pose"], np.eye(4), atol=1e-9)
    lifted = np.eye(4)
    lifted[2, 3] = 30
    np.testing.assert_allclose(bodies["plate@lifted"]["pose"], lifted, atol=1e-9)
    c, s = math.cos(math.pi / 2), math.sin(math.pi / 2)
    turned = np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 30], [0, 0, 0, 1]])
    np.testing.assert_allclose(bodies["plate@turned"]["pose"], turned, atol=1e-9)
    assert all(b["dof"] == 0 for b in bodies.values())


@needs_engine
def test_explain_adds_the_trace(capsys):
    out = solve_json("w4_pin.yaml", capsys, "--explain")
    assert out["trace"] and {"rule", "link"} <= set(out["trace"][0])


@needs_engine
def test_readable_output(capsys):
    assert run(["solve", str(EXAMPLES / "w4_pin.rapt")]) == 0
    text = capsys.readouterr().out
    assert "underconstrained" in text and "pin@s1" in text and "revolute" in text


@needs_engine
@pytest.mark.parametrize("suffix", [".yaml", ".rapt"])
def test_gear_pair_meshed_then_held(suffix: str, capsys):
    """g1 turned 30 deg by the stop; g2 follows by -30·20/40 = -15 deg about (30, 0)."""
    bodies = underconstrained_bodies(f"gear_pair{suffix}", capsys)
    for gear in ("g1@meshed", "g2@meshed"):
        assert (bodies[gear]["dof"], bodies[gear]["motion"]) == (1, "revolute")
    np.testing.assert_allclose(bodies["g2@meshed"]["invariants"]["point"][:2], [30, 0], atol=1e-9)
    assert (bodies["g1@held"]["dof"], bodies["g2@held"]["dof"]) == (0, 0)
    a, b = math.radians(30), math.radians(-15)
    g1 = [[math.cos(a), -math.sin(a), 0, 0], [math.sin(a), math.cos(a), 0, 0]]
    np.testing.assert_allclose(np.asarray(bodies["g1@held"]["pose"])[:2], g1, atol=1e-6)
    shift = [30 - 30 * math.cos(b), -30 * math.sin(b), 0]
    rotation = [[math.cos(b), -math.sin(b), 0], [math.sin(b), math.cos(b), 0], [0, 0, 1]]
    np.testing.assert_allclose(np.asarray(bodies["g2@held"]["pose"])[:3, :3], rotation, atol=1e-6)
    np.testing.assert_allclose(translation(bodies["g2@held"]), shift, atol=1e-5)


@needs_engine
@pytest.mark.parametrize("suffix", [".yaml", ".rapt"])
def test_gripper_jaws_open_then_closed_equal_and_opposite(suffix: str, capsys):
    bodies = underconstrained_bodies(f"gripper{suffix}", capsys)
    for jaw in ("ja@open", "jb@open"):
        assert (bodies[jaw]["dof"], bodies[jaw]["motion"]) == (1, "prismatic")
        direction = np.abs(bodies[jaw]["invariants"]["direction"])
        np.testing.assert_allclose(direction, [1, 0, 0], atol=1e-9)
    assert (bodies["ja@closed"]["dof"], bodies["jb@closed"]["dof"]) == (0, 0)
    np.testing.assert_allclose(bodies["ja@closed"]["pose"][0], [1, 0, 0, 0.5], atol=1e-9)
    np.testing.assert_allclose(bodies["jb@closed"]["pose"][0], [1, 0, 0, -0.5], atol=1e-9)


@needs_engine
@pytest.mark.parametrize("suffix", [".yaml", ".rapt"])
def test_box_on_table_with_a_corner_on_the_wall_keeps_two_dof(suffix: str, capsys):
    box = underconstrained_bodies(f"higher_pairs{suffix}", capsys)["box@s1"]
    assert box["dof"] == 2
    pose = np.asarray(box["pose"])
    assert (pose @ [1, 1, 0, 1])[0] == pytest.approx(5.0, abs=1e-6)  # corner on the wall
    np.testing.assert_allclose(pose[:3, 2], [0, 0, 1], atol=1e-6)  # upright on the table
    assert pose[2, 3] == pytest.approx(0.0, abs=1e-6)


@needs_engine
@pytest.mark.parametrize("columns", ["40", "140", "400"])
def test_explain_text_names_rule_link_places_and_dof(capsys, monkeypatch, columns):
    """The four-bar's trace: each joint's two relations (with their lines) intersect to a
    revolute, and the loop goes to the residue solver: 4 dof along the chains from the
    world (crank 1, rocker 1, coupler 2 through the crank), 1 after closing it. One line
    per step whatever the terminal's width."""
    monkeypatch.setenv("COLUMNS", columns)
    assert run(["solve", str(EXAMPLES / "four_bar.rapt"), "--explain"]) == 0
    lines = [line for line in capsys.readouterr().out.splitlines() if ": " in line]
    assert (
        "intersect: world -> crank@s1 [against crank.bottom ground.top @s1 (line 32);"
        " fits crank.hole_a ground.pin_a @s1 (line 33)] dof 2 -> 1 (revolute)"
    ) in lines
    assert (
        "intersect: crank@s1 -> coupler@s1 [against coupler.bottom crank.top @s1 (line 36);"
        " fits coupler.hole_b crank.pin_b @s1 (line 37)] dof 2 -> 1 (revolute)"
    ) in lines
    assert any(
        line.startswith("residue: coupler@s1, crank@s1, rocker@s1 dof 4 -> 1 (1 solution")
        for line in lines
    )


@needs_engine
def test_explain_text_says_where_a_merged_body_ended(capsys):
    assert run(["solve", str(EXAMPLES / "stack_and_move.rapt"), "--explain"]) == 0
    text = capsys.readouterr().out
    assert "plate@lifted fixed relative to" in text or "fixed relative to plate@lifted" in text
    assert "offset [0.0, 0.0, 30.0]" in text or "offset [0.0, 0.0, -30.0]" in text


V_GROOVE = """\
# a bar in a 120-degree V-groove, the groove's normals typed with {digits}-decimal cosines
units: mm
bodies:
  block:
    fixed: true
    features:
      left:  {{type: plane, point: [-5, 0, 0], normal: [{cosine}, 0, 0.5]}}
      right: {{type: plane, point: [5, 0, 0], normal: [-{cosine}, 0, 0.5]}}
  bar:
    features:
      a: {{type: plane, point: [-5, 0, 0], normal: [-0.8660254037844386, 0, -0.5]}}
      b: {{type: plane, point: [5, 0, 0], normal: [0.8660254037844386, 0, -0.5]}}
situations:
  - name: s1
    relations:
      - [against, bar.a, block.left]
      - [against, bar.b, block.right]
"""


def groove_json(tmp_path: Path, capsys, *extra: str, cosine: str = "0.866") -> dict:
    path = tmp_path / "groove.yaml"
    path.write_text(V_GROOVE.format(cosine=cosine, digits=len(cosine) - 2))
    assert run(["solve", str(path), "--json", *extra]) == 0
    return json.loads(capsys.readouterr().out)


@needs_engine
def test_rounded_v_groove_is_prismatic_once_the_tolerance_covers_its_angle(tmp_path, capsys):
    # written to six or five digits, the groove is within the precision its numbers have
    for cosine in ("0.866025", "0.86603"):
        bar = groove_json(tmp_path, capsys, cosine=cosine)["bodies"]["bar@s1"]
        assert (bar["dof"], bar["motion"]) == (1, "prismatic"), cosine
    # written 0.866 (a value as designed, three digits), the typed normals are
    # 120° - 2.54e-5 rad apart (by hand: acos of (1/4 - c²)/(1/4 + c²))
    strict = groove_json(tmp_path, capsys)
    assert strict["status"] == "inconsistent"
    (conflict,) = strict["conflicts"]
    assert conflict["kind"] == "angle"
    assert conflict["value"] == pytest.approx(2.5404e-5, rel=1e-4)
    assert conflict["needed_tolerance"] == 2.6e-5
    assert strict["suggested_tolerance"] == 2.6e-5
    loose = groove_json(tmp_path, capsys, "--tolerance", "3e-5")
    assert loose["status"] == "underconstrained"
    bar = loose["bodies"]["bar@s1"]
    assert (bar["dof"], bar["motion"]) == (1, "prismatic")
    assert "suggested_tolerance" not in loose
    # an explicit angle tolerance overrides the one following --tolerance
    held = groove_json(tmp_path, capsys, "--tolerance", "3e-5", "--angle-tolerance", "1e-6")
    assert held["status"] == "inconsistent"
    angle_only = groove_json(tmp_path, capsys, "--angle-tolerance", "3e-5")
    assert angle_only["bodies"]["bar@s1"]["motion"] == "prismatic"


@needs_engine
def test_the_table_says_how_far_to_loosen_the_tolerance(tmp_path, capsys):
    path = tmp_path / "groove.yaml"
    path.write_text(V_GROOVE.format(cosine="0.866", digits=3))
    assert run(["solve", str(path)]) == 0
    out = capsys.readouterr().out
    assert "nearly consistent: loosen the tolerance to 2.6e-05 (--tolerance 2.6e-05)" in out


@needs_engine
def test_motion_of_a_task_takes_the_angle_tolerance(capsys):
    task = str(EXAMPLES / "w4_pin.yaml")
    assert run(["motion", task, "--json", "--tolerance", "1e-6", "--angle-tolerance", "1e-6"]) == 0
    assert json.loads(capsys.readouterr().out)["parts"]


@pytest.mark.parametrize("value", ["abc", "0", "-1", "1", "nan"])
@pytest.mark.parametrize("option", ["--tolerance", "--angle-tolerance"])
@pytest.mark.parametrize("command", ["solve", "motion"])
def test_a_bad_tolerance_exits_2_naming_the_option(command, option, value, capsys):
    assert run([command, str(EXAMPLES / "w4_pin.yaml"), option, value]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    (line,) = captured.err.splitlines()
    assert line.startswith(f"assemblykit: {option}: ")


@needs_engine
def test_png_draws_the_solution_and_names_the_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
):
    png = tmp_path / "peg.png"
    assert run(["solve", str(EXAMPLES / "peg_in_block.yaml"), "--json", "--png", str(png)]) == 0
    out, err = capsys.readouterr()
    assert json.loads(out)["status"] == "underconstrained"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert err.strip() == f"wrote {png}"


@pytest.mark.parametrize("name", ["missing/peg.png", "peg.gif"])
def test_a_bad_png_path_exits_2_before_reading_the_task(
    name: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
):
    # the task does not exist either: the output is checked first
    assert run(["solve", str(tmp_path / "nosuch.yaml"), "--png", str(tmp_path / name)]) == 2
    err = capsys.readouterr().err
    assert "--png" in err and len(err.strip().splitlines()) == 1
    assert not list(tmp_path.rglob("*.png")) and not list(tmp_path.rglob("*.gif"))


NEW_TASKS = Path(__file__).parent / "inference" / "tasks"


@needs_engine
def test_a_conflict_through_an_action_names_it_and_the_poses_say_what_they_leave_out(capsys):
    """The plate lifted 30 into s2 but said to sit on the table there: the seat of s1,
    the move and the seat of s2 conflict by 30; the pins take no part. The poses printed
    are those without the three, and the answer says so."""
    assert run(["solve", str(NEW_TASKS / "plate_lifted_on_the_table.rapt"), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["status"] == "inconsistent"
    (conflict,) = out["conflicts"]
    assert [name.split(" @")[0] for name in conflict["relations"]] == [
        "against plate.bottom table.top",
        "move plate plate.hole_1 by 30",
        "against plate.bottom table.top",
    ]
    assert conflict["message"] == "distance mismatch 30 between planes 1 and 2"
    assert out["valid_without"] == conflict["relations"]
    # without the seats and the move, the pins leave the plate a slide along z in
    # "stacked", and nothing holds it in "lifted"
    plate = out["bodies"]["plate@stacked"]
    assert (plate["dof"], plate["motion"]) == (1, "prismatic")
    assert out["bodies"]["plate@lifted"]["dof"] == 6
    assert run(["solve", str(NEW_TASKS / "plate_lifted_on_the_table.rapt")]) == 0
    text = " ".join(capsys.readouterr().out.split())
    assert "poses and freedoms hold only without: against plate.bottom table.top @stacked" in text


@needs_engine
def test_the_gimbal_head_is_named_spherical(capsys):
    assert run(["solve", str(NEW_TASKS / "gimbal.rapt"), "--json"]) == 0
    head = json.loads(capsys.readouterr().out)["bodies"]["head@s1"]
    assert (head["dof"], head["motion"], head["invariants"]) == (
        3,
        "spherical",
        {"center": [0, 0, 0]},
    )
