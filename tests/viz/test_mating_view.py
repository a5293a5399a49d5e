"""The two-layer graph of a mating problem (viz/mating_view.py): every candidate pair
drawn, the pairs each law deleted faded, the first configuration's pairs bold."""

from __future__ import annotations

from collections import Counter
from pathlib import Path

import pytest
from matplotlib.image import imread

import assemblykit
from assemblykit.mating.search import LAWS
from assemblykit.viz.mating_view import CHOSEN, FADED, mating_figure, write_mating_png

MATING = Path(assemblykit.__file__).parent / "examples" / "mating"


def pairs(figure) -> dict[str, object]:
    """The arcs of the candidate pairs, by gid."""
    return {
        a.get_gid(): a
        for axes in figure.axes
        for a in axes.get_children()
        if (a.get_gid() or "").startswith("pair ")
    }


def test_the_bold_pairs_are_exactly_those_of_the_first_configuration():
    problem = assemblykit.load_problem(MATING / "example1.yaml")
    result = assemblykit.mate(problem)
    drawn = pairs(mating_figure(problem, result))
    expected = {
        f"pair {c.goal.number} {c.goal.first}.{c.first} {c.goal.second}.{c.second} {CHOSEN}"
        for c in result.configurations[0].pairs
    }
    assert len(expected) == 3
    assert {g for g in drawn if g.endswith(CHOSEN)} == expected
    widest = max(a.get_linewidth() for g, a in drawn.items() if not g.endswith(CHOSEN))
    assert all(drawn[g].get_linewidth() > widest for g in expected)


def test_every_candidate_is_drawn_and_each_law_fades_what_it_deleted():
    problem = assemblykit.load_problem(MATING / "example1.yaml")
    result = assemblykit.mate(problem)
    drawn = pairs(mating_figure(problem, result))
    assert len(drawn) == sum(sizes[0] for sizes in result.statistics.values()) == 15
    faded = Counter((int(g.split(" ")[1]), law) for g in drawn for law in LAWS if g.endswith(law))
    for goal, sizes in result.statistics.items():
        for k, law in enumerate(LAWS[1:], start=1):
            assert faded[(goal, law)] == sizes[k - 1] - sizes[k], (goal, law)
    for gid, arc in drawn.items():
        opacity = FADED if any(gid.endswith(law) for law in LAWS) else 1.0
        assert arc.get_edgecolor()[3] == pytest.approx(opacity)


def test_a_problem_without_solution_has_no_bold_pair():
    problem = assemblykit.load_problem(MATING / "two_arms.yaml")
    result = assemblykit.mate(problem)
    drawn = pairs(mating_figure(problem, result))
    assert result.emptied is not None and result.emptied.law == "arc consistency"
    assert drawn and all(g.endswith("arc consistency") for g in drawn)


def test_the_png_has_the_figure_size(tmp_path: Path):
    problem = assemblykit.load_problem(MATING / "example1.yaml")
    written = write_mating_png(problem, assemblykit.mate(problem), tmp_path / "m.png", dpi=30)
    assert written.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    width, height = mating_figure(problem, assemblykit.mate(problem)).get_size_inches()
    assert imread(written).shape[:2] == (round(30 * height), round(30 * width))
