"""The results as a notebook shows them: ``repr`` is one short line and ``_repr_html_`` a
short table, with no numpy array dumped, for the contacts of an assembly, a plan, a
solution and a motion report; the contacts stay a ``list``."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
import trimesh

import assemblykit
from assemblykit.geometry.contacts import Contact, Contacts

EXAMPLES = Path(assemblykit.__file__).parent / "examples"
ARRAY_DUMP = re.compile(r"array\(|\[\[|\]\]|dtype|\d\s+\d+\.\d*\s")


@pytest.fixture(scope="module")
def hinge() -> assemblykit.Assembly:
    return assemblykit.load_assembly(EXAMPLES / "motion" / "hinge" / "hinge.yaml")


@pytest.fixture(scope="module")
def boxes() -> assemblykit.Assembly:
    """A unit box resting on another."""
    lower = trimesh.creation.box(bounds=[[0, 0, 0], [1, 1, 1]])
    upper = trimesh.creation.box(bounds=[[0, 0, 1], [1, 1, 2]])
    parts = [assemblykit.Part("lower", lower), assemblykit.Part("upper", upper)]
    return assemblykit.Assembly(parts)


def assert_reads_as_a_table(value: object, rows: int) -> None:
    """``value`` prints as one short line and shows as one table of ``rows`` rows (after
    the header), with no array dumped in either."""
    line = repr(value)
    page = value._repr_html_()  # type: ignore[attr-defined]
    assert "\n" not in line and len(line) < 120, line
    assert page.startswith(f"<p>{line}</p><table>") and page.endswith("</table>"), page
    assert page.count("<tr>") == rows + 1 and len(page) < 200 * (rows + 2)
    assert not ARRAY_DUMP.search(line) and not ARRAY_DUMP.search(page), page


def test_contacts_read_as_a_table_and_stay_a_list(hinge) -> None:
    contacts = hinge.contacts()
    assert isinstance(contacts, list) and isinstance(contacts, Contacts)
    assert repr(contacts) == "Contacts(1 touching pair, 1 planar patch, 1 curved patch)"
    assert_reads_as_a_table(contacts, rows=1)
    cells = re.findall(r"<td>(.*?)</td>", contacts._repr_html_())
    assert cells == ["frame", "door", "1", cells[3], "+Z", "cylindrical"]
    (contact,) = contacts
    assert repr(contact).startswith("Contact(frame, door, 1 planar patch, area ")
    assert repr(contact.curved[0]) == "CurvedPatch(cylindrical, axis +Z, radius 3, inner frame)"
    assert repr(contact.planar[0]).startswith("PlanarPatch(area ")
    for shown in (repr(contact), repr(contact.planar[0]), repr(contact.curved[0])):
        assert "\n" not in shown and not ARRAY_DUMP.search(shown)
    # a list for the code that reads it: equality, slicing, JSON of what it holds
    assert contacts == list(contacts) and contacts[:1] == [contact]
    assert json.loads(json.dumps([c.pair for c in contacts])) == [["frame", "door"]]
    assert hinge.contacts() is contacts
    assert hinge.subset(["door"]).contacts() == []


def test_contacts_of_nothing() -> None:
    empty = Contacts()
    assert repr(empty) == "Contacts(0 touching pairs, 0 planar patches, 0 curved patches)"
    assert_reads_as_a_table(empty, rows=0)
    assert repr(Contacts([Contact("a", "b")])) == (
        "Contacts(1 touching pair, 0 planar patches, 0 curved patches)"
    )


def test_plan_reads_as_a_table(boxes) -> None:
    plan = assemblykit.plan(boxes)
    assert repr(plan) == "Plan(feasible, 1 step, 2 parts)"
    assert_reads_as_a_table(plan, rows=1)
    assert re.findall(r"<td>(.*?)</td>", plan._repr_html_())[:3] == ["1", "upper", "+Z"]


def test_solution_reads_as_a_table() -> None:
    solution = assemblykit.load_task(EXAMPLES / "tasks" / "peg_in_block.yaml").solve()
    assert repr(solution) == "Solution(underconstrained, 6 body instances, 0 conflicts)"
    assert_reads_as_a_table(solution, rows=6)


def test_motion_report_reads_as_a_table(hinge) -> None:
    report = assemblykit.motion(hinge)
    assert repr(report) == "MotionReport(2 moving sets, 2 with freedom, hinge.yaml)"
    assert_reads_as_a_table(report, rows=2)
    assert repr(report["door"]) == "Motion(door, revolute, 1 dof)"


def test_polygon_assembly_reads_as_a_table() -> None:
    hook = assemblykit.load_assembly(EXAMPLES / "planar" / "hook.yaml")
    assert repr(hook) == "PolygonAssembly(2 parts, 2D, hook.yaml)"
    assert_reads_as_a_table(hook, rows=2)
    assert re.findall(r"<td>(.*?)</td>", hook._repr_html_())[3:] == ["peg", "4", "4"]
    assert_reads_as_a_table(hook.contacts(), rows=1)
