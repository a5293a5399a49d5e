"""The .rapt task language: same models as YAML, round trips, syntax and semantic errors."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import assemblykit
from assemblykit.errors import FeatureError, SchemaError, TaskSyntaxError, UnknownNameError
from assemblykit.features import Cone, Frame, Prism, Shaft, Thread, Torus
from assemblykit.io.rapt import parse_rapt, rapt_to_dict, task_to_rapt
from assemblykit.io.tasks import load_task
from assemblykit.model.relations import FeatureRef

EXAMPLES = Path(assemblykit.__file__).parent / "examples" / "tasks"
EXAMPLE_NAMES = sorted(p.stem for p in EXAMPLES.glob("*.rapt"))

SKETCH = """\
units mm
body table fixed
  plane top point (0,0,0) normal (0,0,1)
end
body block
  plane bottom point (0,0,0) normal (0,0,-1)
  hole bore point (5,5,10) axis (0,0,-1) radius 2
end
body peg
  shaft shaft point (0,0,0) axis (0,0,1) radius 2
end
situation s1
  against bottom of block, top of table
  fits shaft of peg, bore of block
end
situation s2
  move peg parallel shaft of peg by -5
  turn block about bore of block by 90 deg
end
"""

EVERY_FEATURE = """\
# every feature type, flags, angles and relation options
units m
body world fixed
  plane top point (0, 0, 0) normal (0, 0, 1)
  thread nut point (0, 0, 0) axis (0, 0, 1) radius 3 lead 1.5 hand left female phase 30 deg
  prism key point (0, 0, 0) axis (0, 0, 1) sides 6 size 2.5 female undirected ref (1, 1, 0)
  cone seat point (1, 2, 3) axis (0, 0, -1) half_angle 0.25 female
  torus ring point (0, 0, 0) axis (1, 0, 0) major_radius 4 minor_radius 0.5
  frame datum matrix ((1, 0, 0, 1), (0, 1, 0, 2), (0, 0, 1, 3), (0, 0, 0, 1))
  socket cup point (0, 0, 1e-3) radius 1
end
body part
  plane bottom point (0, 0, 0) normal (0, 0, -1)
  thread bolt point (0, 0, 0) axis (0, 0, 1) radius 3 lead 1.5 hand left
  prism spline point (0, 0, 0) axis (0, 0, 1) sides 6 size 2.5 undirected
  cone tip point (0, 0, 0) axis (0, 0, 1) half_angle 0.25
  axis spin point (0, 0, 0) axis (0, 1, 0) undirected
  point mark point (1, 1, 1)
  ball knob point (0, 0, 0) radius 1
end
situation s1
  against bottom of part, top of world offset 0.5
  fits bolt of part, nut of world
  angle spin of part, top of world angle 30 deg
  gear spin of part, ring of world ratio -0.5
end
situation s2
  turn part about spin of part
end
situation s3
  move part along bolt of part
end
situation s4
  move part
end
"""


def test_the_sketch_of_the_language_reads_into_the_model():
    task = parse_rapt(SKETCH, "task.rapt")
    assert task.units == "mm"
    assert list(task.bodies) == ["table", "block", "peg"]
    assert task.bodies["table"].fixed and not task.bodies["block"].fixed
    shaft = task.bodies["peg"].features["shaft"]
    assert isinstance(shaft, Shaft) and shaft.radius == 2.0
    np.testing.assert_array_equal(task.bodies["block"].features["bore"].point, [5, 5, 10])
    s1, s2 = task.situations
    assert s1.relations[0].refs == (FeatureRef("block", "bottom"), FeatureRef("table", "top"))
    assert s1.relations[1].kind == "fits"
    assert s1.relations[1].where == "line 14"
    move, turn = s2.actions
    assert (move.kind, move.body, move.along, move.by) == (
        "move",
        "peg",
        FeatureRef("peg", "shaft"),
        -5,
    )
    assert (turn.kind, turn.about, turn.by) == ("turn", FeatureRef("block", "bore"), math.pi / 2)
    assert turn.where == "line 18"


def test_rapt_to_dict_gives_the_task_file_mapping_and_lines():
    data, places = rapt_to_dict(SKETCH)
    assert data["bodies"]["table"] == {
        "fixed": True,
        "features": {"top": {"type": "plane", "point": [0, 0, 0], "normal": [0, 0, 1]}},
    }
    assert data["situations"][1]["actions"] == [
        ["move", "peg", {"along": "peg.shaft", "by": -5}],
        # an angle as written, which the task file reads as the loader of YAML does
        ["turn", "block", {"about": "block.bore", "by": "90 deg"}],
    ]
    assert places["bodies.block.features.bore"] == "line 7"
    assert places["situations[0].relations[0]"] == "line 13"
    assert places["situations[1]"] == "line 16"


def test_every_feature_type_flags_and_options():
    task = parse_rapt(EVERY_FEATURE, "all.rapt")
    world, part = task.bodies["world"].features, task.bodies["part"].features
    nut = world["nut"]
    assert isinstance(nut, Thread)
    assert (nut.hand, nut.male, nut.lead) == ("left", False, 1.5)
    assert nut.phase == pytest.approx(math.pi / 6, abs=1e-15)
    key = world["key"]
    assert isinstance(key, Prism) and (key.sides, key.male, key.directed) == (6, False, False)
    np.testing.assert_allclose(key.ref, [math.sqrt(0.5), math.sqrt(0.5), 0], atol=1e-15)
    assert isinstance(world["seat"], Cone) and world["seat"].male is False
    assert isinstance(world["ring"], Torus) and world["ring"].minor_radius == 0.5
    assert isinstance(world["datum"], Frame)
    np.testing.assert_array_equal(world["datum"].matrix[:3, 3], [1, 2, 3])
    np.testing.assert_array_equal(world["cup"].point, [0, 0, 0.001])
    assert part["spin"].directed is False
    s1 = task.situations[0]
    assert s1.relations[0].options == {"offset": 0.5}
    assert s1.relations[2].options["angle"] == pytest.approx(math.pi / 6, abs=1e-15)
    assert s1.relations[3].options == {"ratio": -0.5}
    (turn,) = task.situations[1].actions
    assert (turn.about, turn.by) == (FeatureRef("part", "spin"), None)
    (move,) = task.situations[2].actions
    assert (move.along, move.by) == (FeatureRef("part", "bolt"), None)
    assert task.situations[3].actions[0].ref is None


@pytest.mark.parametrize("name", EXAMPLE_NAMES)
def test_both_syntaxes_give_equal_models(name: str):
    assert load_task(EXAMPLES / f"{name}.rapt") == load_task(EXAMPLES / f"{name}.yaml")


def test_every_example_comes_in_both_syntaxes():
    assert sorted(p.stem for p in EXAMPLES.glob("*.yaml")) == EXAMPLE_NAMES
    assert len(EXAMPLE_NAMES) >= 8


@pytest.mark.parametrize("name", EXAMPLE_NAMES)
def test_rapt_round_trips_every_example(name: str):
    task = load_task(EXAMPLES / f"{name}.yaml")
    assert parse_rapt(task_to_rapt(task)) == task


def test_rapt_round_trips_every_feature_type():
    task = parse_rapt(EVERY_FEATURE)
    text = task_to_rapt(task)
    assert parse_rapt(text) == task
    assert "  thread nut point (0, 0, 0) axis (0, 0, 1) radius 3 lead 1.5 hand left female" in text
    assert "  against bottom of part, top of world offset 0.5" in text
    assert "  move part parallel bolt of part" in text


def test_written_text_is_readable():
    text = task_to_rapt(parse_rapt(SKETCH))
    assert text.splitlines()[:5] == [
        "units mm",
        "",
        "body table fixed",
        "  plane top point (0, 0, 0) normal (0, 0, 1)",
        "end",
    ]
    assert "  move peg parallel shaft of peg by -5" in text
    assert "  turn block about bore of block by 1.5707963267948966" in text


def test_comments_blank_lines_and_keywords_as_names():
    text = (
        "-- leading comment\n\n"
        "units mm  # trailing comment\n"
        "body end_stop fixed\n"
        "  plane end point (0,0,0) normal (0,0,1) -- a feature called end\n"
        "\n"
        "  # a comment line inside a body\n"
        "  plane fixed point (0,0,1) normal (0,0,1)\n"
        "end\n"
        "body move\n"
        "  plane of point (0,0,0) normal (0,0,-1)\n"
        "end\n"
        "situation s\n"
        "  against of of move, end of end_stop\n"
        "end"
    )
    task = parse_rapt(text)
    assert list(task.bodies["end_stop"].features) == ["end", "fixed"]
    assert task.situations[0].relations[0].refs == (
        FeatureRef("move", "of"),
        FeatureRef("end_stop", "end"),
    )


def syntax_error(text: str) -> TaskSyntaxError:
    with pytest.raises(TaskSyntaxError) as caught:
        parse_rapt(text, "task.rapt")
    return caught.value


def test_syntax_error_gives_line_column_and_what_was_expected():
    error = syntax_error("units mm\nbody peg\n  shaft s point (0,0,0 axis (0,0,1) radius 2\nend\n")
    assert (error.line, error.column) == (3, 24)
    assert str(error) == ("task.rapt: line 3, column 24: unexpected 'axis', expected ')', ','")


def test_syntax_error_for_a_missing_end():
    error = syntax_error("body peg\n  shaft s point (0,0,0) axis (0,0,1) radius 2\n")
    assert (error.line, error.column) == (3, 1)
    assert "unexpected end of file" in str(error)
    assert "'end'" in str(error)


def test_syntax_error_for_a_stray_character():
    error = syntax_error("units mm\nbody peg @\nend\n")
    assert (error.line, error.column) == (2, 10)
    assert str(error).startswith("task.rapt: line 2, column 10: unexpected character '@'")


def test_syntax_error_for_a_relation_without_of():
    error = syntax_error(
        "body a fixed\nend\nbody b\nend\nsituation s\n  against top, bottom of b\nend\n"
    )
    assert (error.line, error.column) == (6, 14)
    assert "expected 'of'" in str(error)


def test_semantic_errors_name_the_line():
    with pytest.raises(SchemaError) as caught:
        parse_rapt("body a fixed\n  plan top point (0,0,0) normal (0,0,1)\nend\n", "t.rapt")
    assert str(caught.value).startswith("t.rapt: line 2: unknown feature type 'plan'")
    with pytest.raises(FeatureError) as caught:
        parse_rapt("body a fixed\n  hole h point (0,0,0) axis (0,0,1) radius -1\nend\n", "t.rapt")
    assert str(caught.value) == "t.rapt: line 2: radius must be a positive number, got -1"
    with pytest.raises(UnknownNameError) as caught:
        parse_rapt(SKETCH.replace("fits shaft of peg, bore", "fits shaft of peg, bor"), "t.rapt")
    assert str(caught.value).startswith("t.rapt: line 14: body 'block' has no feature 'bor'")
    with pytest.raises(FeatureError) as caught:
        parse_rapt(SKETCH.replace("fits shaft of peg", "against shaft of peg"), "t.rapt")
    assert str(caught.value).startswith("t.rapt: line 14: against cannot relate")


def test_duplicates_name_both_lines():
    with pytest.raises(SchemaError) as caught:
        parse_rapt("body a fixed\nend\nbody a\nend\n", "t.rapt")
    assert str(caught.value) == "t.rapt: line 3: duplicate body 'a' (first at line 1)"
    with pytest.raises(SchemaError) as caught:
        parse_rapt("body a\n  point p point (0,0,0)\n  point p point (1,0,0)\nend\n", "t.rapt")
    assert (
        str(caught.value) == "t.rapt: line 3: duplicate feature 'p' in body 'a' (first at line 2)"
    )
    with pytest.raises(SchemaError) as caught:
        parse_rapt("body a\n  shaft s radius 1 radius 2\nend\n", "t.rapt")
    assert str(caught.value) == "t.rapt: line 2, column 20: radius given twice for feature s"


def test_a_bare_word_that_is_not_a_flag():
    with pytest.raises(SchemaError) as caught:
        parse_rapt("body a\n  shaft s point (0,0,0) axis (0,0,1) radius 1 hollow\nend\n", "t.rapt")
    assert str(caught.value) == (
        "t.rapt: line 2, column 47: 'hollow' needs a value "
        "(bare words: male, female, directed, undirected)"
    )


@pytest.mark.parametrize("option", ["offset 90 deg", "offset 1.5 rad"], ids=["degrees", "radians"])
def test_an_angle_written_for_a_length_is_refused_with_its_line(tmp_path, option):
    path = tmp_path / "angle.rapt"
    path.write_text(
        "units mm\nbody a fixed\n  plane p point (0,0,0) normal (0,0,1)\nend\n"
        "body b\n  plane q point (0,0,0) normal (0,0,-1)\nend\n"
        f"situation s\n  against q of b, p of a {option}\nend\n"
    )
    with pytest.raises(SchemaError, match=r"line 9.*offset is a length in model units"):
        load_task(path)
