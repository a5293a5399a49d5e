"""Every reference to the documentation resolves: the sources, the guides, the README,
the benchmarks and the example scripts cite ``docs/NAME.md`` files that exist, and their
sections as headings those files have, in one of two forms:

* ``docs/algebra.md §2.5`` (more numbers may follow: ``§3, §5.1``, ``§2.4-§2.5``) for a
  numbered heading (``### 2.5 Coset intersection``);
* ``docs/planning.md, "Fasteners"`` for a heading by its text, or by the part of it
  before a colon (``"Under gravity"`` for ``Under gravity: plans that stand``).

Inside ``docs/`` a link ``[algebra.md](algebra.md)`` may take the place of the path. No
citation of files the repository does not have remains (``ALGEBRA.md``, ``DESIGN.md``),
and papers are cited by author and year (``Wilson & Latombe 1992``), not by the name of a
local copy (``seed 004``)."""

from __future__ import annotations

import re
from collections.abc import Iterator
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SCANNED = ("src", "docs", "README.md", "benchmarks", "examples")
SUFFIXES = {".py", ".md", ".rapt", ".yaml", ".yml", ".lark", ".txt", ".toml"}

FENCE = re.compile(r"^\s*```")
HEADING = re.compile(r"^#{1,6}\s+(.+?)\s*#*\s*$")
NUMBERED = re.compile(r"^(\d+(?:\.\d+)*)\.?\s+(.*)$")
# a line break inside a docstring, a comment (Python, .lark, .rapt) or a paragraph
BREAK = re.compile(r"[ \t]*\n[ \t]*(?:(?:#|//|--)[ \t]*)?")
DOCUMENT = r"(?:docs/(?P<path>[\w-]+\.md)|\[[\w-]+\.md\]\((?P<link>[\w-]+\.md)(?:#[\w-]*)?\))"
NUMBER = r"§\d+(?:\.\d+)*"
BY_NUMBER = re.compile(DOCUMENT + rf"\s+(?P<numbers>{NUMBER}(?:\s*(?:,|-|–|and)\s*{NUMBER})*)")
BY_NAME = re.compile(DOCUMENT + r',\s+"(?P<name>[^"]{1,120})"')
ANY_PATH = re.compile(r"(?<![\w/.])docs/([\w/-]+\.md)")
FORBIDDEN = re.compile(r"ALGEBRA\.md|DESIGN\.md|\b[Ss]eed\s+00\d")


def headings(markdown: str) -> tuple[set[str], set[str]]:
    """The section numbers (``2.5``) and the names (whole, and the part before a colon;
    numbered headings also without their number) of the headings of a Markdown text,
    outside code blocks."""
    numbers: set[str] = set()
    names: set[str] = set()
    fenced = False
    for line in markdown.splitlines():
        if FENCE.match(line):
            fenced = not fenced
            continue
        found = HEADING.match(line)
        if fenced or not found:
            continue
        text = found.group(1)
        numbered = NUMBERED.match(text)
        titles = [text]
        if numbered:
            numbers.add(numbered.group(1))
            titles.append(numbered.group(2))
        for title in titles:
            names.add(title)
            names.add(title.split(":")[0].strip())
    return numbers, names


def citations(text: str) -> Iterator[tuple[str, str]]:
    """``(document, section)`` for each section cited in ``text``: ``§2.5`` by number,
    ``"Fasteners"`` by name (line breaks and comment markers inside a citation read as
    one space)."""
    flat = BREAK.sub(" ", text)
    for found in BY_NUMBER.finditer(flat):
        document = found.group("path") or found.group("link")
        for number in re.findall(NUMBER, found.group("numbers")):
            yield document, number
    for found in BY_NAME.finditer(flat):
        yield found.group("path") or found.group("link"), f'"{found.group("name")}"'


def scanned_files() -> list[Path]:
    """The text files of the scanned folders and files, without build output."""
    found: list[Path] = []
    for name in SCANNED:
        path = ROOT / name
        candidates = [path] if path.is_file() else sorted(path.rglob("*"))
        found += [
            f
            for f in candidates
            if f.is_file()
            and f.suffix in SUFFIXES
            and not any(p.endswith(".egg-info") or p == "__pycache__" for p in f.parts)
        ]
    return found


@pytest.fixture(scope="module")
def texts() -> dict[str, str]:
    return {str(f.relative_to(ROOT)): f.read_text(encoding="utf-8") for f in scanned_files()}


def test_the_citation_reader_finds_both_forms() -> None:
    text = (
        "(docs/algebra.md §3, §5.1; Liu 1997 §2) and docs/algebra.md §2.4-§2.5 or\n"
        '    docs/planning.md, "How a plan is\n    found"; [algebra.md](algebra.md) §6, W3;\n'
        '# docs/planning.md, "Under\n# gravity"; see docs/tutorial.md.'
    )
    assert list(citations(text)) == [
        ("algebra.md", "§3"),
        ("algebra.md", "§5.1"),
        ("algebra.md", "§2.4"),
        ("algebra.md", "§2.5"),
        ("algebra.md", "§6"),
        ("planning.md", '"How a plan is found"'),
        ("planning.md", '"Under gravity"'),
    ]
    numbers, names = headings(
        "# Title\n## 1. Conventions\n```\n# a comment\n```\n### 2.5 Coset intersection\n"
        "## Under gravity: plans that stand\n"
    )
    assert numbers == {"1", "2.5"}
    assert {"1. Conventions", "Conventions", "Coset intersection"} <= names
    assert {"Under gravity: plans that stand", "Under gravity"} <= names
    assert "a comment" not in names


def test_every_cited_document_and_section_exists(texts: dict[str, str]) -> None:
    documents = {f.name: headings(f.read_text(encoding="utf-8")) for f in ROOT.glob("docs/*.md")}
    cited = 0
    missing = []
    for source, text in texts.items():
        for path in ANY_PATH.findall(BREAK.sub(" ", text)):
            if not (ROOT / "docs" / path).is_file():
                missing.append(f"{source}: docs/{path}")
        for document, section in citations(text):
            cited += 1
            if document not in documents:
                missing.append(f"{source}: docs/{document}")
                continue
            numbers, names = documents[document]
            known = numbers if section.startswith("§") else names
            if section.strip('"§') not in known:
                missing.append(f"{source}: docs/{document} {section}")
    assert cited > 150
    assert missing == []


def test_no_citation_of_files_the_repository_does_not_have(texts: dict[str, str]) -> None:
    found = [
        f"{source}:{text.count(chr(10), 0, match.start()) + 1}: {match.group(0)}"
        for source, text in texts.items()
        for match in FORBIDDEN.finditer(text)
    ]
    assert found == []
