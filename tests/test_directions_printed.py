"""Directions as people read them (formatting.direction; docs/architecture.md, "Numbers for
people"): every command's text and HTML on bundled examples writes a direction as ``+X``
or as rounded components, never with an exponent (``2.952e-05``), never as ``-0`` and never
as a numpy array (``[-0. -0. -1.]``). The commands run in-process (cli_runs.py)."""

from __future__ import annotations

import html
import json
import re
from html.parser import HTMLParser
from pathlib import Path

import pytest

import assemblykit
from assemblykit import cli
from cli_runs import run

EXAMPLES = Path(assemblykit.__file__).parent / "examples"
WIDE = 1000
"""Console width of these runs: no table cell wraps a direction over two lines."""

NUMBER = re.compile(r"^[-+]?(?:\d+\.?\d*|\.\d+)(?:e[-+]?\d+)?$|^[-+]?(?:nan|inf)$")
TUPLE = re.compile(r"\(([^()]*)\)")
NUMPY_ARRAY = re.compile(
    r"\[\s*[-+]?\d+\.\d*(?:e[-+]?\d+)?(?:\s+[-+]?\d+\.\d*(?:e[-+]?\d+)?)+\s*\]"
)
SIGNED_ZERO = re.compile(r"^-0*\.?0*$")


def vectors(text: str) -> list[list[str]]:
    """The components of every parenthesised list of two or more numbers in ``text``
    (``(1, 0, 0)``, a twist ``(0, 0, 1; 0, 0.5, 0)``)."""
    found = []
    for inside in TUPLE.findall(text):
        items = [item.strip() for item in re.split(r"[,;]", inside)]
        if len(items) >= 2 and all(NUMBER.match(item) for item in items):
            found.append(items)
    return found


def faults(text: str) -> list[str]:
    """What ``text`` writes as float noise: components with an exponent or equal to
    ``-0``, and numpy arrays."""
    bad = [
        f"({', '.join(items)})"
        for items in vectors(text)
        if any("e" in item.lower() or SIGNED_ZERO.match(item) for item in items)
    ]
    return bad + NUMPY_ARRAY.findall(text)


class _Text(HTMLParser):
    """The text a browser shows of a page (no scripts, no styles), and the data of the
    report's script (its captions and labels)."""

    def __init__(self) -> None:
        super().__init__()
        self.parts: list[str] = []
        self.hidden = 0

    def handle_starttag(self, tag: str, attrs: object) -> None:
        self.hidden += tag in ("script", "style")

    def handle_endtag(self, tag: str) -> None:
        self.hidden -= tag in ("script", "style")

    def handle_data(self, data: str) -> None:
        if not self.hidden:
            self.parts.append(data)


def page_text(page: str) -> str:
    """The visible text of an HTML page and the captions its report script shows."""
    parser = _Text()
    parser.feed(page)
    shown = list(parser.parts)
    script = re.search(r"const P = (\{.*?\});\n", page)
    if script:
        data = json.loads(script.group(1))
        shown += data["captions"] + data["labels"]
    return html.unescape("\n".join(shown))


@pytest.fixture
def wide(monkeypatch: pytest.MonkeyPatch):
    """The command line's console as wide as ``WIDE``, for these runs only."""
    monkeypatch.setattr(cli, "PLAIN_WIDTH", WIDE)
    cli.console.cache_clear()
    yield
    cli.console.cache_clear()


def test_the_checks_find_float_noise():
    assert faults("along (1, 2.952e-05, -6.795e-06) and (0, 1.786e-07, 1)") == [
        "(1, 2.952e-05, -6.795e-06)",
        "(0, 1.786e-07, 1)",
    ]
    assert faults("normals (-0, -0, -1)") == ["(-0, -0, -1)"]
    assert faults("│ base │ 1 │ [-0. -0. -1.] │") == ["[-0. -0. -1.]"]
    assert faults("+Z, (0.7071, 0, -0.7071), (0, 0, 1; 0, -0.5, 0), 8.37e-06 mm") == []
    assert page_text("<p>a &lt;b&gt;</p><script>const x = 1e-06;</script>") == "a <b>"


RUNS = [
    ("plan", "planar/hook.yaml"),
    ("blocking", "motion/interlock/interlock.yaml"),
    ("blocking", "puzzles/key_in_steps"),
    ("blocking", "puzzles/staircase.xmpuzzle"),
    ("blocking", "motion/gearbox/gearbox.yaml"),
    ("blocking", "planar/hook.yaml"),
    ("contacts", "motion/interlock/interlock.yaml"),
    ("contacts", "puzzles/key_in_steps"),
    ("motion", "motion/ball_joint/ball_joint.yaml"),
    ("motion", "motion/hinge/hinge.yaml"),
]


@pytest.mark.parametrize("command, example", RUNS, ids=[f"{c}-{e}" for c, e in RUNS])
def test_command_text_writes_directions_without_noise(capsys, wide, command, example):
    code, out, err = run(capsys, command, str(EXAMPLES / example))
    assert code == 0, err
    assert vectors(out) or re.search(r"[-+][XYZ]\b", out), out  # directions are shown
    assert faults(out) == [], out


def test_rigid_twists_are_rounded_components(capsys, wide):
    code, out, err = run(
        capsys, "blocking", str(EXAMPLES / "motion/hinge/hinge.yaml"), "--motion", "rigid"
    )
    assert code == 0, err
    assert any(";" in " ".join(items) or len(items) == 6 for items in vectors(out)), out
    assert faults(out) == [], out


def test_the_plan_report_and_the_step_table_write_directions_without_noise(capsys, wide, tmp_path):
    report, table = tmp_path / "plan.html", tmp_path / "plan.csv"
    example = EXAMPLES / "motion/hinge/hinge.yaml"
    code, out, err = run(capsys, "plan", str(example), "--html", str(report), "--out", str(table))
    assert code == 0, err
    assert "+Z" in out and faults(out) == []
    shown = page_text(report.read_text(encoding="utf-8"))
    assert "along " in shown and faults(shown) == []
    assert faults(table.read_text(encoding="utf-8").split("\n", 1)[1]) == []


def test_the_demo_and_its_report_write_directions_without_noise(capsys, wide, tmp_path):
    code, out, err = run(capsys, "demo", "--out", str(tmp_path))
    assert code == 0, err
    assert faults(out) == []
    shown = page_text((tmp_path / "gearbox_report.html").read_text(encoding="utf-8"))
    assert "along +Z" in shown and "along +X" in shown
    assert faults(shown) == [], shown
