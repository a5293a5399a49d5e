"""The public names of tests/public_api.py: each resolves, each deprecated alias warns
and answers as its new name, and every name the documents show is listed."""

from __future__ import annotations

import importlib
import pkgutil
import re
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

import assemblykit
from assemblykit.algebra import SymmetryGroup, intersect_groups
from assemblykit.blocking.directions import DirectionTable
from assemblykit.io.polygons import load_polygons
from assemblykit.model.assembly import Assembly, Part
from assemblykit.model.packings import box_mesh
from assemblykit.tolerance import Tolerance
from public_api import DEPRECATED, PUBLIC_NAMES

ROOT = Path(__file__).resolve().parents[1]
DOCUMENTS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
PLANAR = Path(assemblykit.__file__).parent / "examples" / "planar"

FENCE = re.compile(r"^```[^\n]*\n(.*?)^```", re.DOTALL | re.MULTILINE)
SPAN = re.compile(r"`([^`\n]+)`")
FROM_IMPORT = re.compile(
    r"^[ \t]*(?:>>> )?from[ \t]+(assemblykit(?:\.\w+)*)[ \t]+import[ \t]+(\([^)]*\)|[^\n#]+)",
    re.MULTILINE,
)
IMPORT = re.compile(r"^[ \t]*(?:>>> )?import[ \t]+(assemblykit(?:\.\w+)*)", re.MULTILINE)
DOTTED = re.compile(r"\bassemblykit(?:\.[A-Za-z_]\w*)+")


def resolve(dotted: str) -> object:
    """The object a dotted name stands for: its longest importable module prefix, then
    attributes (of modules or classes) for the rest."""
    parts = dotted.split(".")
    for end in range(len(parts), 0, -1):
        module_name = ".".join(parts[:end])
        try:
            found: object = importlib.import_module(module_name)
        except ModuleNotFoundError as error:
            missing = error.name or ""
            if module_name != missing and not module_name.startswith(missing + "."):
                raise
            continue
        for attribute in parts[end:]:
            found = getattr(found, attribute)
        return found
    raise ModuleNotFoundError(f"no module for {dotted!r}")


def shown_names(markdown: str) -> set[str]:
    """The assemblykit names a Markdown text shows in code (fenced blocks and inline
    spans): modules and names of ``import`` and ``from ... import`` statements and
    dotted ``assemblykit.x.y`` names."""
    blocks = FENCE.findall(markdown)
    code = [*blocks, *SPAN.findall(FENCE.sub("", markdown))]
    names: set[str] = set()
    for text in code:
        names.update(DOTTED.findall(text))
        names.update(IMPORT.findall(text))
        for module, imported in FROM_IMPORT.findall(text):
            for item in imported.strip("()").split(","):
                name = item.split(" as ")[0].strip()
                if name:
                    names.add(f"{module}.{name}")
    return names


def alias_warnings(caught: list[warnings.WarningMessage]) -> list[str]:
    """The messages of the deprecated aliases' warnings among ``caught``."""
    return [
        str(w.message)
        for w in caught
        if issubclass(w.category, DeprecationWarning) and "is deprecated; use" in str(w.message)
    ]


def two_boxes() -> Assembly:
    """A unit box resting on another: it lifts off along +Z."""
    return Assembly(
        [
            Part("lower", box_mesh([0, 0, 0], [1, 1, 1])),
            Part("upper", box_mesh([0, 0, 1], [1, 1, 2])),
        ]
    )


def group_pairs() -> list[tuple[tuple[Any, ...], str]]:
    """Pairs of symmetry groups and the description of their intersection: a pin in a
    hole on a plane, two cyclic groups about one axis, a cyclic group and a revolute
    about a parallel axis."""
    z = (0, 0, 1)
    cylinder, plane = SymmetryGroup.cylindrical((0, 0, 0), z), SymmetryGroup.planar(z)
    four, six = SymmetryGroup.cyclic((0, 0, 0), z, 4), SymmetryGroup.cyclic((0, 0, 0), z, 6)
    beside = SymmetryGroup.revolute((1, 0, 0), z)
    return [
        ((cylinder, plane), "revolute about line through (0, 0, 0) along +Z"),
        ((cylinder, plane, Tolerance()), "revolute about line through (0, 0, 0) along +Z"),
        ((four, six), "fixed, 2 symmetric positions"),
        ((four, beside), "fixed"),
    ]


def separable_cases() -> list[tuple[tuple[Any, ...], str]]:
    """Assemblies and whether they come apart by translations: two boxes, the planar
    peg in a hook, and the plug stuck in its bottle (with the block, it comes out)."""
    bottle = load_polygons(PLANAR / "bottle.yaml")
    return [
        ((two_boxes(),), "True"),
        ((load_polygons(PLANAR / "hook.yaml"),), "True"),
        ((bottle,), "False"),
        ((bottle, ["block", "plug"]), "True"),
        ((bottle, ["bottle", "plug"]), "False"),
    ]


def direction_tables() -> list[tuple[tuple[Any, ...], str]]:
    """Tables of DBGs and the direction kept per distinct DBG (the one closest to a
    coordinate axis): two directions with one DBG and a third with another."""
    directions = [[0.6, 0.0, 0.8], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]]
    table = DirectionTable.from_arcs(("a", "b"), directions, [[(0, 1)], [(0, 1)], []])
    return [((table,), "[1, 2]")]


def plan_cases() -> list[tuple[tuple[Any, ...], str]]:
    """Plans of two boxes, the planar hook and the bottle."""
    return [
        ((two_boxes(),), "Plan(feasible, 1 step, 2 parts)"),
        ((load_polygons(PLANAR / "hook.yaml"),), "Plan(feasible, 1 step, 2 parts)"),
        (
            (load_polygons(PLANAR / "bottle.yaml"),),
            "Plan(infeasible, stuck: block, bottle, plug, 0 steps, 3 parts)",
        ),
    ]


EXAMPLES: dict[str, Callable[[], list[tuple[tuple[Any, ...], str]]]] = {
    "assemblykit.algebra.SymmetryGroup.intersect": group_pairs,
    "assemblykit.blocking.queries.separable_by_translations": separable_cases,
    "assemblykit.planning.sequence.distinct_directions": direction_tables,
    "assemblykit.planning.sequence.plan": plan_cases,
    "assemblykit.planning.sequence.separable_by_translations": separable_cases,
}


def summary(result: object) -> str:
    """A group by its description, any other result by its repr."""
    return result.describe() if isinstance(result, SymmetryGroup) else repr(result)


def same(old: object, new: object) -> bool:
    """Whether two results are the same answer: equal groups, equal documented JSON, or
    equal values."""
    if isinstance(old, SymmetryGroup) and isinstance(new, SymmetryGroup):
        return old.equals(new) and new.equals(old)
    to_dict = getattr(old, "to_dict", None)
    if to_dict is not None:
        return bool(to_dict() == new.to_dict())
    return old == new


@pytest.mark.parametrize("name", PUBLIC_NAMES)
def test_public_name_resolves_without_a_deprecation(name: str) -> None:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        found = resolve(name)
    assert found is not None
    assert alias_warnings(caught) == []


def test_names_are_listed_once_and_aliases_point_at_listed_names() -> None:
    assert len(set(PUBLIC_NAMES)) == len(PUBLIC_NAMES)
    assert set(EXAMPLES) == set(DEPRECATED)
    for old, new in DEPRECATED.items():
        assert old not in PUBLIC_NAMES
        assert new in PUBLIC_NAMES


@pytest.mark.parametrize("old", sorted(DEPRECATED))
def test_deprecated_alias_warns_and_answers_as_its_new_name(old: str) -> None:
    new = DEPRECATED[old]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        replacement = resolve(new)
    assert alias_warnings(caught) == []
    assert callable(replacement)
    for args, expected in EXAMPLES[old]():
        with pytest.warns(DeprecationWarning, match=re.escape(f"is deprecated; use {new}")) as w:
            answer = resolve(old)(*args)
        (message,) = alias_warnings(list(w))
        assert message.endswith(f" is deprecated; use {new}")
        assert ".".join(old.split(".")[-2:]) in message
        assert all(m.filename == __file__ for m in w if str(m.message) == message)
        result = replacement(*args)
        assert summary(answer) == summary(result) == expected
        assert same(answer, result)


def test_symmetry_group_intersect_as_a_bound_method() -> None:
    cylinder = SymmetryGroup.cylindrical((0, 0, 0), (0, 0, 1))
    plane = SymmetryGroup.planar((0, 0, 1))
    with pytest.warns(DeprecationWarning, match="use assemblykit.algebra.intersect_groups"):
        met = cylinder.intersect(plane, tol=Tolerance())
    assert met.dof == 1
    assert met.equals(intersect_groups(cylinder, plane, Tolerance()))


def test_a_module_without_the_name_still_raises_attribute_error() -> None:
    queries = importlib.import_module("assemblykit.blocking.queries")
    sequence = importlib.import_module("assemblykit.planning.sequence")
    for module in (queries, sequence):
        with pytest.raises(AttributeError, match="no attribute 'nowhere'"):
            _ = module.nowhere


def test_shown_names_reads_imports_and_dotted_names_in_code_only() -> None:
    text = (
        "Prose about assemblykit.prose_only and `assemblykit.span.name(x)`.\n\n"
        "```python\n"
        "import assemblykit\n"
        "from assemblykit.pkg import (\n    first,\n    second as other,\n)\n"
        ">>> from assemblykit.more import third  # a comment\n"
        "assemblykit.call.target(1).attribute\n"
        "```\n"
    )
    assert shown_names(text) == {
        "assemblykit",
        "assemblykit.span.name",
        "assemblykit.pkg",
        "assemblykit.pkg.first",
        "assemblykit.pkg.second",
        "assemblykit.more",
        "assemblykit.more.third",
        "assemblykit.call.target",
    }


def test_every_name_the_documents_show_is_listed() -> None:
    shown = {name: doc.name for doc in DOCUMENTS for name in shown_names(doc.read_text())}
    assert "assemblykit.planning.planner.separable_by_translations" in shown
    assert "assemblykit.render.render" in shown
    listed = {*PUBLIC_NAMES, *DEPRECATED}
    missing = sorted(f"{name} ({shown[name]})" for name in shown if name not in listed)
    assert missing == []


def test_every_package_export_is_listed() -> None:
    packages = [assemblykit.__name__]
    packages += [
        info.name
        for info in pkgutil.walk_packages(assemblykit.__path__, "assemblykit.")
        if info.ispkg
    ]
    exported = {
        f"{package}.{name}"
        for package in packages
        for name in getattr(importlib.import_module(package), "__all__", ())
    }
    assert "assemblykit.algebra.intersect_groups" in exported
    assert sorted(exported - set(PUBLIC_NAMES)) == []


def test_the_top_level_namespace_is_the_public_api() -> None:
    listed = dir(assemblykit)
    assert listed == sorted(assemblykit.__all__)
    for helper in ("Any", "annotations", "importlib", "typing", "errors"):
        assert helper not in listed
    star: dict[str, object] = {}
    exec("from assemblykit import *", star)
    assert sorted(k for k in star if k != "__builtins__") == sorted(assemblykit.__all__)
    # submodules still import, as attributes and by name
    errors = importlib.import_module("assemblykit.errors")
    assert assemblykit.errors is errors and errors.InputError is assemblykit.InputError
    exec("from assemblykit import algebra, geometry", star)
    assert star["algebra"] is importlib.import_module("assemblykit.algebra")


def test_the_inputs_and_outputs_users_meet_are_exported() -> None:
    homes = {
        "Part": "assemblykit.model.assembly",
        "Gravity": "assemblykit.planning.stability",
        "PolygonAssembly": "assemblykit.api.assembly",
        "Contact": "assemblykit.geometry.contacts",
        "Contacts": "assemblykit.geometry.contacts",
        "Solution": "assemblykit.inference.solution",
        "Motion": "assemblykit.motion.freedom",
        "MotionReport": "assemblykit.motion.freedom",
        "Plan": "assemblykit.planning.sequence",
        "Step": "assemblykit.planning.sequence",
        "DirectionalBlockingGraph": "assemblykit.blocking.dbg",
        "NonDirectionalBlockingGraph": "assemblykit.blocking.ndbg",
        "MatingProblem": "assemblykit.mating.problem",
        "MatingResult": "assemblykit.mating.search",
        "InputError": "assemblykit.errors",
    }
    for name, module in homes.items():
        assert name in assemblykit.__all__ and f"assemblykit.{name}" in PUBLIC_NAMES
        assert getattr(assemblykit, name) is getattr(importlib.import_module(module), name)
    # what the command line builds, built from the top level
    boxes = assemblykit.Assembly(
        [
            assemblykit.Part("lower", box_mesh([0, 0, 0], [1, 1, 1])),
            assemblykit.Part("upper", box_mesh([0, 0, 1], [1, 1, 2])),
        ]
    )
    found = assemblykit.plan(boxes, gravity=assemblykit.Gravity(friction=0.5))
    assert isinstance(found, assemblykit.Plan) and isinstance(found.steps[0], assemblykit.Step)
    assert isinstance(boxes.contacts(), assemblykit.Contacts)


@pytest.mark.parametrize(
    ("old", "new"),
    [
        (
            "assemblykit.blocking.free_cones.lattice_cells",
            "assemblykit.blocking.lattice.lattice_cells",
        ),
        (
            "assemblykit.geometry.contacts.triangle_overlaps",
            "assemblykit.geometry.contacts.group_overlaps",
        ),
        (
            "assemblykit.geometry.occlusion.triangle_overlaps",
            "assemblykit.geometry.occlusion.clip_triangles",
        ),
        (
            "assemblykit.blocking.polygons.PolygonAssembly",
            "assemblykit.model.polygons.PolygonAssembly",
        ),
        (
            "assemblykit.blocking.polygons.PolygonContacts",
            "assemblykit.geometry.polygons.PolygonContacts",
        ),
        (
            "assemblykit.blocking.polygons.counter_clockwise",
            "assemblykit.geometry.polygons.counter_clockwise",
        ),
        (
            "assemblykit.blocking.polygons.edge_contacts",
            "assemblykit.geometry.polygons.edge_contacts",
        ),
        (
            "assemblykit.blocking.polygons.section_polygons",
            "assemblykit.geometry.polygons.section_polygons",
        ),
    ],
)
def test_module_functions_that_moved_or_were_renamed_still_work(old: str, new: str) -> None:
    with pytest.warns(DeprecationWarning, match=re.escape(f"is deprecated; use {new}")):
        found = resolve(old)
    assert found is resolve(new)
