"""The YAML/JSON task file (docs/tutorial.md §1): reading, writing and every kind of bad input."""

from __future__ import annotations

import copy
import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

import assemblykit
from assemblykit.errors import FeatureError, InputError, SchemaError, UnknownNameError
from assemblykit.features import Ball, Hole, Plane, Shaft
from assemblykit.io.spec import parse_task, task_to_dict
from assemblykit.io.tasks import load_task
from assemblykit.model.relations import FeatureRef

EXAMPLES = Path(assemblykit.__file__).parent / "examples" / "tasks"
EXAMPLE_NAMES = sorted(p.stem for p in EXAMPLES.glob("*.yaml"))

BASE: dict[str, Any] = {
    "units": "mm",
    "bodies": {
        "table": {
            "fixed": True,
            "features": {"top": {"type": "plane", "point": [0, 0, 0], "normal": [0, 0, 1]}},
        },
        "block": {
            "features": {
                "bottom": {"type": "plane", "point": [0, 0, 0], "normal": [0, 0, -1]},
                "bore": {"type": "hole", "point": [5, 5, 10], "axis": [0, 0, -1], "radius": 2},
            }
        },
        "peg": {
            "features": {
                "shaft": {"type": "shaft", "point": [0, 0, 0], "axis": [0, 0, 1], "radius": 2},
                "tip": {"type": "ball", "point": [0, 0, 0], "radius": 1},
            }
        },
    },
    "situations": [
        {
            "name": "s1",
            "relations": [
                ["against", "block.bottom", "table.top"],
                ["fits", "peg.shaft", "block.bore"],
            ],
        },
        {
            "name": "s2",
            "actions": [["move", "peg", {"along": "peg.shaft", "by": 5}]],
            "relations": [],
        },
    ],
}


def base() -> dict[str, Any]:
    return copy.deepcopy(BASE)


def write_yaml(tmp_path: Path, data: Any, name: str = "task.yaml") -> Path:
    path = tmp_path / name
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def test_the_design_example_reads_into_bodies_features_relations_and_actions(tmp_path: Path):
    task = load_task(write_yaml(tmp_path, base()))
    assert task.units == "mm"
    assert task.source == "task.yaml"
    assert list(task.bodies) == ["table", "block", "peg"]
    assert task.bodies["table"].fixed and not task.bodies["peg"].fixed
    bore = task.bodies["block"].features["bore"]
    assert isinstance(bore, Hole)
    np.testing.assert_array_equal(bore.point, [5, 5, 10])
    np.testing.assert_array_equal(bore.axis, [0, 0, -1])
    assert bore.radius == 2.0
    assert isinstance(task.bodies["table"].features["top"], Plane)
    assert isinstance(task.bodies["peg"].features["shaft"], Shaft)
    assert isinstance(task.bodies["peg"].features["tip"], Ball)
    s1, s2 = task.situations
    assert (s1.name, s2.name) == ("s1", "s2")
    assert [r.kind for r in s1.relations] == ["against", "fits"]
    assert s1.relations[1].refs == (FeatureRef("peg", "shaft"), FeatureRef("block", "bore"))
    assert s1.relations[0].where == "situations[0].relations[0]"
    (action,) = s2.actions
    assert (action.kind, action.body, action.by) == ("move", "peg", 5.0)
    assert action.along == FeatureRef("peg", "shaft") and action.about is None
    assert action.where == "situations[1].actions[0]"


def test_angles_in_degrees_become_radians(tmp_path: Path):
    data = base()
    data["situations"][1]["actions"] = [["turn", "peg", {"about": "peg.shaft", "by": "90 deg"}]]
    data["bodies"]["peg"]["features"]["cone"] = {
        "type": "cone",
        "point": [0, 0, 0],
        "axis": [0, 0, 1],
        "half_angle": "30 deg",
    }
    data["situations"][0]["relations"].append(
        ["angle", "peg.shaft", "block.bore", {"angle": "45 deg"}]
    )
    task = load_task(write_yaml(tmp_path, data))
    assert task.situations[1].actions[0].by == pytest.approx(math.pi / 2, abs=1e-15)
    assert task.bodies["peg"].features["cone"].half_angle == pytest.approx(math.pi / 6, abs=1e-15)
    assert task.situations[0].relations[2].options == {"angle": pytest.approx(math.pi / 4)}


@pytest.mark.parametrize(
    ("where", "text"),
    [("relation", "90 deg"), ("relation", "1.5 rad"), ("action", "5 deg")],
)
def test_an_angle_written_for_a_length_is_refused(tmp_path: Path, where: str, text: str):
    data = base()
    if where == "relation":
        data["situations"][0]["relations"][0].append({"offset": text})
        fault = r"situations\[0\]\.relations\[0\].*offset is a length in model units"
    else:
        data["situations"][1]["actions"][0][2]["by"] = text
        fault = r"situations\[1\]\.actions\[0\].*'by' must be a finite length"
    with pytest.raises(SchemaError, match=fault):
        load_task(write_yaml(tmp_path, data))


def test_units_default_to_millimetres(tmp_path: Path):
    data = base()
    del data["units"]
    assert load_task(write_yaml(tmp_path, data)).units == "mm"


def test_json_and_yaml_give_the_same_task(tmp_path: Path):
    (tmp_path / "task.json").write_text(json.dumps(base()))
    assert load_task(tmp_path / "task.json") == load_task(write_yaml(tmp_path, base()))


@pytest.mark.parametrize("name", EXAMPLE_NAMES)
def test_task_to_dict_round_trips_every_example(name: str, tmp_path: Path):
    task = load_task(EXAMPLES / f"{name}.yaml")
    again = parse_task(task_to_dict(task), "copy.yaml")
    assert again == task
    (tmp_path / "copy.json").write_text(json.dumps(task_to_dict(task)))
    assert load_task(tmp_path / "copy.json") == task


def test_task_to_dict_leaves_out_defaults_and_keeps_options():
    data = base()
    data["situations"][0]["relations"][0].append({"offset": 2})
    task = parse_task(data, "t.yaml")
    out = task_to_dict(task)
    assert out["bodies"]["block"]["features"]["bore"] == {
        "type": "hole",
        "point": [5.0, 5.0, 10.0],
        "axis": [0.0, 0.0, -1.0],
        "radius": 2.0,
    }
    assert out["bodies"]["table"]["fixed"] is True and "fixed" not in out["bodies"]["peg"]
    assert out["situations"][0]["relations"][0] == [
        "against",
        "block.bottom",
        "table.top",
        {"offset": 2},
    ]
    assert out["situations"][1]["actions"] == [["move", "peg", {"along": "peg.shaft", "by": 5.0}]]


def test_a_different_feature_makes_a_different_task():
    other = base()
    other["bodies"]["block"]["features"]["bore"]["radius"] = 3
    assert parse_task(other) != parse_task(base())


def fault(tmp_path: Path, data: Any, error: type[InputError]) -> str:
    """The one-line message of loading ``data`` as task.yaml, checked to be ``error``."""
    with pytest.raises(error) as caught:
        load_task(write_yaml(tmp_path, data))
    assert type(caught.value) is error
    return str(caught.value)


def test_unknown_relation_names_file_and_place(tmp_path: Path):
    data = base()
    data["situations"][1]["relations"] = [["agains", "block.bottom", "table.top"]]
    message = fault(tmp_path, data, SchemaError)
    assert message.startswith(
        "task.yaml: situations[1].relations[0]: unknown relation 'agains' (expected one of"
    )


def test_unknown_feature_type(tmp_path: Path):
    data = base()
    data["bodies"]["peg"]["features"]["shaft"]["type"] = "shaftt"
    message = fault(tmp_path, data, SchemaError)
    assert message.startswith("task.yaml: bodies.peg.features.shaft: unknown feature type 'shaftt'")


def test_zero_normal(tmp_path: Path):
    data = base()
    data["bodies"]["table"]["features"]["top"]["normal"] = [0, 0, 0]
    message = fault(tmp_path, data, FeatureError)
    assert message == "task.yaml: bodies.table.features.top: normal must be a non-zero vector"


def test_negative_radius(tmp_path: Path):
    data = base()
    data["bodies"]["block"]["features"]["bore"]["radius"] = -2
    message = fault(tmp_path, data, FeatureError)
    assert message == (
        "task.yaml: bodies.block.features.bore: radius must be a positive number, got -2"
    )


def test_against_between_a_plane_and_a_shaft(tmp_path: Path):
    data = base()
    data["situations"][0]["relations"][0] = ["against", "block.bottom", "peg.shaft"]
    message = fault(tmp_path, data, FeatureError)
    assert message.startswith("task.yaml: situations[0].relations[0]: against cannot relate")
    assert "plane 'bottom'" in message and "shaft 'shaft'" in message


def test_reference_to_a_missing_feature(tmp_path: Path):
    data = base()
    data["situations"][0]["relations"][1] = ["fits", "peg.shaft", "block.boer"]
    message = fault(tmp_path, data, UnknownNameError)
    assert message == (
        "task.yaml: situations[0].relations[1]: body 'block' has no feature 'boer' "
        "(features: bottom, bore)"
    )


def test_unknown_body_in_a_relation_and_in_an_action(tmp_path: Path):
    data = base()
    data["situations"][0]["relations"][0] = ["against", "blok.bottom", "table.top"]
    message = fault(tmp_path, data, UnknownNameError)
    assert message == (
        "task.yaml: situations[0].relations[0]: unknown body 'blok' (bodies: table, block, peg)"
    )
    data = base()
    data["situations"][1]["actions"] = [["move", "pge"]]
    message = fault(tmp_path, data, UnknownNameError)
    assert message.startswith("task.yaml: situations[1].actions[0]: unknown body 'pge'")


def test_duplicate_body_names_are_caught_with_their_line(tmp_path: Path):
    path = tmp_path / "task.yaml"
    path.write_text("bodies:\n  a: {fixed: true}\n  a: {}\nsituations: [{name: s1}]\n")
    with pytest.raises(SchemaError) as caught:
        load_task(path)
    assert str(caught.value) == "task.yaml: line 3: duplicate key 'a'"


def test_duplicate_situation_names(tmp_path: Path):
    data = base()
    data["situations"][1]["name"] = "s1"
    message = fault(tmp_path, data, SchemaError)
    assert message == "task.yaml: situations[1]: duplicate situation name 's1'"


def test_move_along_a_feature_without_an_axis(tmp_path: Path):
    data = base()
    data["situations"][1]["actions"] = [["move", "peg", {"along": "peg.tip", "by": 5}]]
    message = fault(tmp_path, data, FeatureError)
    assert message == (
        "task.yaml: situations[1].actions[0]: cannot move along peg.tip: a ball has no axis"
    )


def test_malformed_yaml_names_the_line(tmp_path: Path):
    path = tmp_path / "task.yaml"
    path.write_text("units: mm\nbodies:\n  table: {fixed: true\nsituations: []\n")
    with pytest.raises(SchemaError) as caught:
        load_task(path)
    assert str(caught.value).startswith("task.yaml: line 4, column 11: malformed YAML")


def test_malformed_json_names_the_line(tmp_path: Path):
    path = tmp_path / "task.json"
    path.write_text('{"units": "mm",\n "bodies": {,\n}')
    with pytest.raises(SchemaError) as caught:
        load_task(path)
    assert str(caught.value) == (
        "task.json: line 2, column 13: malformed JSON: Expecting property name enclosed in "
        "double quotes"
    )


def test_schema_errors_name_the_field(tmp_path: Path):
    data = base()
    data["bodies"]["peg"]["colour"] = "red"
    assert fault(tmp_path, data, SchemaError) == "task.yaml: bodies.peg: unknown field 'colour'"
    data = base()
    del data["situations"][0]["name"]
    assert fault(tmp_path, data, SchemaError) == "task.yaml: situations[0]: missing field 'name'"
    data = base()
    data["units"] = "furlong"
    assert fault(tmp_path, data, SchemaError).startswith("task.yaml: units: Input should be")
    data = base()
    data["bodies"]["peg"]["fixed"] = "yes"
    assert fault(tmp_path, data, SchemaError).startswith("task.yaml: bodies.peg.fixed:")


def test_names_must_be_identifiers(tmp_path: Path):
    data = base()
    data["situations"][0]["name"] = "first step"
    message = fault(tmp_path, data, SchemaError)
    assert message == (
        "task.yaml: situations[0].name: 'first step' is not a valid name (letters, digits and _)"
    )


def test_bad_action_shapes(tmp_path: Path):
    data = base()
    data["situations"][1]["actions"] = [["move", "peg", {"along": "peg.shaft", "speed": 5}]]
    assert fault(tmp_path, data, SchemaError) == (
        "task.yaml: situations[1].actions[0]: unknown action option(s) speed "
        "(allowed: along, about, by)"
    )
    data["situations"][1]["actions"] = [["move", "peg", {"by": 5}]]
    assert fault(tmp_path, data, SchemaError) == (
        "task.yaml: situations[1].actions[0]: 'move' needs a feature to move along"
    )
    data["situations"][1]["actions"] = [["move", "peg", {"along": "peg.shaft", "by": "far"}]]
    assert fault(tmp_path, data, SchemaError) == (
        "task.yaml: situations[1].actions[0].by: 'by' must be a finite length, got 'far'"
    )
    data["situations"][1]["actions"] = [["jump", "peg"]]
    assert fault(tmp_path, data, SchemaError) == (
        "task.yaml: situations[1].actions[0]: unknown action 'jump' (expected move or turn)"
    )


def test_files_that_cannot_be_read(tmp_path: Path):
    with pytest.raises(InputError) as caught:
        load_task(tmp_path / "absent.yaml")
    assert "cannot read the task file" in str(caught.value)
    (tmp_path / "task.txt").write_text("units mm\n")
    with pytest.raises(InputError) as caught:
        load_task(tmp_path / "task.txt")
    assert str(caught.value) == (
        "task.txt: unknown task file type '.txt' (expected .yaml, .yml, .json or .rapt)"
    )
    (tmp_path / "list.yaml").write_text("- 1\n- 2\n")
    with pytest.raises(SchemaError):
        load_task(tmp_path / "list.yaml")


def test_the_public_load_task_reads_the_same_task():
    path = EXAMPLES / "peg_in_block.yaml"
    assert assemblykit.load_task(path) == load_task(path)
