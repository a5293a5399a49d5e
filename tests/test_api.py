"""The Python API for people: ``dir(assemblykit)``, one-line reprs without arrays, tables
in notebooks, results indexed by name that behave as mappings, and the Examples in the
public docstrings (run here with doctest)."""

from __future__ import annotations

import doctest
import importlib
import re
from pathlib import Path

import numpy as np
import pytest

import assemblykit
from assemblykit.blocking.dbg import DirectionalBlockingGraph
from assemblykit.planning.sequence import Plan, Step

EXAMPLES = Path(assemblykit.__file__).parent / "examples"
DOCUMENTED = (
    "assemblykit",
    "assemblykit.formatting",
    "assemblykit.io.exports",
    "assemblykit.render",
    "assemblykit.viz.explode",
    "assemblykit.viz.plots",
    "assemblykit.viz.task_view",
    "assemblykit.viz.mating_view",
)


@pytest.mark.parametrize("name", DOCUMENTED)
def test_the_examples_in_the_docstrings_hold(name: str):
    module = importlib.import_module(name)
    result = doctest.testmod(module, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert result.attempted > 0 and result.failed == 0


def test_dir_lists_the_public_api_and_every_name_resolves():
    listed = dir(assemblykit)
    for name in ("load_task", "load_assembly", "motion", "blocking_graph", "plan", "mate"):
        assert name in listed and name in assemblykit.__all__
    for name in assemblykit.__all__:
        assert getattr(assemblykit, name) is not None
    with pytest.raises(AttributeError, match="no attribute 'nosuch'"):
        assemblykit.nosuch  # noqa: B018


def test_reprs_are_one_short_line_without_arrays_or_paths():
    task = assemblykit.load_task(EXAMPLES / "tasks" / "peg_in_block.rapt")
    solution = task.solve()
    hinge = assemblykit.load_assembly(EXAMPLES / "motion" / "hinge" / "hinge.yaml")
    ndbg = assemblykit.blocking_graph(hinge)
    shown = [repr(x) for x in (task, solution, solution["peg@s1"], hinge, ndbg)]
    assert shown[2] == "BodyInstanceResult(peg@s1, cylindrical, 2 dof)"
    assert shown[3] == "Assembly(2 parts, mm, hinge.yaml)"
    # the hinge's sphere arrangement: 6 vertices, 12 edges, 8 faces; one contact
    assert shown[4] == "NonDirectionalBlockingGraph(infinitesimal, 2 parts, 1 contact, 26 regions)"
    for text in shown:
        assert "\n" not in text and len(text) < 120
        assert "array" not in text and str(EXAMPLES) not in text


def test_blocking_graph_and_plan_reprs_say_it_in_words():
    dbg = DirectionalBlockingGraph(("a", "b"), np.array([0.0, -1.0, 0.0]), frozenset({("a", "b")}))
    assert repr(dbg) == "DirectionalBlockingGraph(-Y, 2 parts, 1 arc)"
    step = Step(("lid",), np.array([0.0, 0.0, 1.0]), ("base",), ())
    plan = Plan(("base", "lid"), (step,), (), None, 1)
    assert repr(plan) == "Plan(feasible, 1 step, 2 parts)"
    assert repr(step) == "Step(lid along +Z)"
    assert plan._repr_html_() == (
        "<p>Plan(feasible, 1 step, 2 parts)</p><table><tr><th>step</th><th>move</th>"
        "<th>direction</th><th>motion</th><th>away from</th></tr><tr><td>1</td><td>lid</td>"
        "<td>+Z</td><td>translation</td><td>1 part</td></tr></table>"
    )


def test_notebook_tables_and_mappings_by_name():
    task = assemblykit.load_task(EXAMPLES / "tasks" / "peg_in_block.rapt")
    solution = task.solve()
    assert list(solution) == list(solution.bodies) and "nosuch@s1" not in solution
    cells = re.findall(r"<td>(.*?)</td>", solution._repr_html_())
    assert cells[:4] == ["table@s1", "0", "fixed", "(0, 0, 0)"]
    assert re.findall(r"<td>(.*?)</td>", task._repr_html_())[:3] == [
        "table",
        "yes",
        "top, wall_x, wall_y",
    ]
    hinge = assemblykit.load_assembly(EXAMPLES / "motion" / "hinge" / "hinge.yaml")
    assert "<th>volume (mm³)</th>" in hinge._repr_html_()
    report = assemblykit.motion(hinge)
    assert list(report) == ["frame", "door"] and "door" in report and "lid" not in report
    assert "<td>door</td><td>revolute</td><td>1</td>" in report._repr_html_()


def test_coset_and_mating_reprs_say_it_in_words():
    from assemblykit.algebra import Coset, SymmetryGroup, se3

    revolute = SymmetryGroup.revolute(np.zeros(3), np.array([0.0, 0.0, 1.0]))
    assert repr(Coset(revolute, se3.translation([0.0, 0.0, 5.0]))) == (
        "Coset(revolute, 1 dof, axis through (0, 0, 0) along +Z)"
    )
    assert repr(Coset(SymmetryGroup.identity(), se3.translation([1.0, 2.0, 1e-17]))) == (
        "Coset(fixed, 0 dof, at (1, 2, 0))"
    )
    helical = SymmetryGroup.helical(np.array([1.0, 0.0, 0.0]), np.array([0.0, -1.0, 0.0]), 0.5)
    assert repr(Coset(helical, np.eye(4))) == (
        "Coset(helical, 1 dof, axis through (1, 0, 0) along -Y, pitch 0.5)"
    )
    square = assemblykit.features.Prism(point=(0, 0, 0), axis=(0, 0, 1), sides=4, size=1)
    assert (
        repr(Coset(square.group(), np.eye(4))) == "Coset(prismatic, 1 dof, along +Z, 4 components)"
    )
    mating = EXAMPLES / "mating"
    problem = assemblykit.load_problem(mating / "example1.yaml")
    assert repr(problem) == "MatingProblem(4 bodies, 3 goals, mm, example1.yaml)"
    assert repr(assemblykit.mate(problem)) == "MatingResult(solved, 8 configurations, 2 found)"
    arms = assemblykit.mate(assemblykit.load_problem(mating / "two_arms.yaml"))
    assert repr(arms) == "MatingResult(no solution, goal 1 emptied by the arc consistency law)"
    for shown in (repr(problem), repr(arms)):
        assert "array" not in shown and str(EXAMPLES) not in shown


def test_the_loaded_values_carry_the_methods_the_model_leaves_to_the_algorithms():
    from assemblykit.geometry.contacts import assembly_contacts, assembly_surfaces
    from assemblykit.inference import solve_task
    from assemblykit.model.assembly import Assembly
    from assemblykit.model.task import Task

    assert not hasattr(Task, "solve") and not hasattr(Assembly, "contacts")
    task = assemblykit.load_task(EXAMPLES / "tasks" / "peg_in_block.rapt")
    assert isinstance(task, Task) and isinstance(task, assemblykit.Task)
    assert task.solve().to_dict() == solve_task(task).to_dict()
    hinge = assemblykit.load_assembly(EXAMPLES / "motion" / "hinge" / "hinge.yaml")
    assert isinstance(hinge, Assembly) and isinstance(hinge, assemblykit.Assembly)
    assert hinge.contacts() is assembly_contacts(hinge)
    assert hinge.surfaces("door") is assembly_surfaces(hinge, "door")
    assert [type(f) for f in hinge.features("door")] == [
        type(s.feature()) for s in hinge.surfaces("door")
    ]
    door = hinge.subset(["door"])
    assert isinstance(door, assemblykit.Assembly) and door.contacts() == []
