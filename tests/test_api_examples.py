"""The functions ``assemblykit`` exports say, numpydoc style, what they take
(``Parameters``), give (``Returns``) and raise (``Raises``), and show it in an
``Examples`` section whose doctest runs here."""

from __future__ import annotations

import doctest
import importlib
import inspect
import re
from collections.abc import Callable
from typing import Any

import pytest

import assemblykit

# each exported function by its home (``assemblykit.motion`` is also the callable
# package, whose docstring describes the package)
FUNCTIONS = {
    "load_task": "assemblykit.api.task",
    "load_assembly": "assemblykit.api.assembly",
    "load_problem": "assemblykit.io.problem",
    "motion": "assemblykit.motion.freedom",
    "blocking_graph": "assemblykit.blocking.graphs",
    "plan": "assemblykit.planning.planner",
    "mate": "assemblykit.mating.search",
    "write_report": "assemblykit.viz.viewer",
    "write_plan": "assemblykit.io.exports",
    "write_gltf": "assemblykit.io.exports",
}
SECTIONS = ("Parameters", "Returns", "Raises", "Examples")


def home(name: str) -> Callable[..., Any]:
    """The function ``assemblykit.NAME`` stands for, from its module."""
    function: Callable[..., Any] = getattr(importlib.import_module(FUNCTIONS[name]), name)
    return function


def test_the_functions_listed_are_exported() -> None:
    assert set(FUNCTIONS) <= set(assemblykit.__all__)
    for name in FUNCTIONS:
        assert inspect.isfunction(home(name)), name
        exported = getattr(assemblykit, name)
        assert exported is home(name) or (name == "motion" and callable(exported))


@pytest.mark.parametrize("name", FUNCTIONS)
def test_the_docstring_has_the_numpydoc_sections(name: str) -> None:
    function = home(name)
    text = inspect.getdoc(function) or ""
    found = re.findall(r"^(\w+)\n-+$", text, re.MULTILINE)
    assert found == list(SECTIONS), name
    for parameter in list(inspect.signature(function).parameters)[:3]:
        assert re.search(rf"^{parameter} : ", text, re.MULTILINE), (name, parameter)


@pytest.mark.parametrize("name", FUNCTIONS)
def test_the_example_runs(name: str) -> None:
    function = home(name)
    (test,) = doctest.DocTestFinder().find(function, name, module=False, globs={})
    report: list[str] = []
    runner = doctest.DocTestRunner(optionflags=doctest.NORMALIZE_WHITESPACE)
    result = runner.run(test, out=report.append)
    assert result.attempted > 0 and result.failed == 0, "".join(report)
