"""Bad input never passes as an answer and never ends as an internal error.

Every case runs one command in-process on tiny files written into ``tmp_path`` and
expects either exit 2 with one line on stderr naming the file or option at fault, or
exit 0 where the input is valid; never exit 1, and no file written except the output
paths the command was given. A small hypothesis part mutates and truncates the bundled
task, ``.rapt`` and mating files.
"""

from __future__ import annotations

import json
import os
import re
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from assemblykit.cli import main
from assemblykit.errors import AssemblyKitError, InputError
from assemblykit.io.compas import load_compas
from assemblykit.io.documents import MAX_DEPTH, read_yaml
from assemblykit.io.meshes import load_manifest, load_mesh_folder
from assemblykit.io.problem import load_problem
from assemblykit.io.tasks import load_task
from assemblykit.outputs import atomic_output

EXAMPLES = Path(__file__).resolve().parents[1] / "src" / "assemblykit" / "examples"

TASK = """units: mm
bodies:
  table:
    fixed: true
    features:
      top: {type: plane, point: [0, 0, 0], normal: [0, 0, 1]}
  block:
    features:
      bottom: {type: plane, point: [0, 0, 0], normal: [0, 0, -1]}
      bore: {type: hole, point: [0, 0, 1], axis: [0, 0, -1], radius: 0.2}
situations:
  - name: s1
    relations:
      - [against, block.bottom, table.top]
"""

RAPT = """units mm
body table fixed
  plane top point (0, 0, 0) normal (0, 0, 1)
end
body block
  plane bottom point (0, 0, 0) normal (0, 0, -1)
end
situation s1
  against bottom of block, top of table
end
"""

PROBLEM = (EXAMPLES / "mating" / "one_socket.yaml").read_text()
POLYGONS = "parts:\n  a: [[0, 0], [2, 0], [2, 1], [0, 1]]\n  b: [[0, 1], [2, 1], [2, 2], [0, 2]]\n"


def cube_obj(x0: float, z0: float, coordinate: str | None = None) -> str:
    """A unit cube at (x0, 0, z0) as OBJ text; ``coordinate`` replaces its last z."""
    corners = [(x0 + i, j, z0 + k) for i in (0, 1) for j in (0, 1) for k in (0, 1)]
    lines = [f"v {x} {y} {z}" for x, y, z in corners]
    if coordinate is not None:
        lines[-1] = f"v {x0 + 1} 1 {coordinate}"
    quads = [(1, 2, 4, 3), (5, 7, 8, 6), (1, 5, 6, 2), (3, 4, 8, 7), (1, 3, 7, 5), (2, 6, 8, 4)]
    for a, b, c, d in quads:
        lines += [f"f {a} {b} {c}", f"f {a} {c} {d}"]
    return "\n".join(lines) + "\n"


FLAT_OBJ = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n"


def manifest(pose_b: str = "{translation: [0, 0, 1]}") -> str:
    return f"parts:\n  - {{name: a, mesh: a.obj}}\n  - {{name: b, mesh: b.obj, pose: {pose_b}}}\n"


def write_assembly(folder: Path, b_obj: str | None = None, text: str | None = None) -> Path:
    """Two stacked unit cubes: ``a.obj``, ``b.obj`` and the manifest ``asm.yaml``."""
    (folder / "a.obj").write_text(cube_obj(0, 0))
    (folder / "b.obj").write_text(b_obj if b_obj is not None else cube_obj(0, 0))
    path = folder / "asm.yaml"
    path.write_text(text if text is not None else manifest())
    return path


BOMB = "a: &a [x, x, x, x, x, x, x, x, x]\n" + "".join(
    f"{chr(98 + i)}: &{chr(98 + i)} [" + ", ".join([f"*{chr(97 + i)}"] * 9) + "]\n"
    for i in range(8)
)
DEEP = "a: " + "[" * 5000 + "]" * 5000 + "\n"
DEEP_BLOCK = "a:\n" + "".join("  " * (i + 1) + "a:\n" for i in range(300))
NOT_UTF8 = {
    "binary": b"\x89PNG\r\n\x1a\n\x00\xff\xfe",
    "latin1": "units: mm # caf\u00e9\n".encode("latin-1"),
    "utf16": TASK.encode("utf-16"),
}


@dataclass(frozen=True)
class Case:
    """One command line built in a folder: ``argv`` from the folder, the text the one
    stderr line must contain (``None``: valid input, exit 0), the outputs it may write."""

    name: str
    build: Callable[[Path], list[str]]
    names: str | None
    outputs: tuple[str, ...] = ()


def _file(name: str, content: str | bytes) -> Callable[[Path], Path]:
    def make(folder: Path) -> Path:
        path = folder / name
        if isinstance(content, bytes):
            path.write_bytes(content)
        else:
            path.write_text(content)
        return path

    return make


def on(command: str, name: str, content: str | bytes, *extra: str) -> Callable[[Path], list[str]]:
    """``command FILE extra...`` with FILE written from ``content``."""
    make = _file(name, content)
    return lambda folder: [command, str(make(folder)), *extra]


def _loop(folder: Path, command: str) -> list[str]:
    """``command --out`` into a folder behind two symbolic links naming each other."""
    (folder / "one").symlink_to(folder / "two")
    (folder / "two").symlink_to(folder / "one")
    return [command, "--out", str(folder / "one" / "report")]


def on_assembly(
    command: str, *extra: str, b_obj: str | None = None, text: str | None = None
) -> Callable[[Path], list[str]]:
    """``command asm.yaml extra...`` with the two-cube assembly (options relative to the
    folder where they start with ``@``)."""

    def build(folder: Path) -> list[str]:
        path = write_assembly(folder, b_obj, text)
        (folder / "d.png").mkdir()
        return [command, str(path), *(str(folder / e[1:]) if e[:1] == "@" else e for e in extra)]

    return build


def on_folder(config: str | bytes) -> Callable[[Path], list[str]]:
    """``motion FOLDER`` for a mesh folder with ``config.json``."""

    def build(folder: Path) -> list[str]:
        meshes = folder / "meshes"
        meshes.mkdir()
        write_assembly(meshes)
        (meshes / "asm.yaml").unlink()
        _file("config.json", config)(meshes)
        return ["motion", str(meshes)]

    return build


def on_link(command: str, option: str, name: str, dangling: bool = False):
    """``command asm.yaml option LINK``, LINK a symbolic link to a file (or to nothing)."""

    def build(folder: Path) -> list[str]:
        argv = on_assembly(command)(folder)
        target = folder / f"real{Path(name).suffix}"
        if not dangling:
            target.write_text("not to be replaced\n")
        (folder / name).symlink_to(target)
        return [*argv, option, str(folder / name)]

    return build


def latin1_comment_obj(folder: Path) -> list[str]:
    """``contacts asm.yaml`` where ``b.obj`` opens with a Latin-1 comment (trimesh
    guesses the encoding of mesh text with charset_normalizer)."""
    path = write_assembly(folder)
    (folder / "b.obj").write_bytes("# caf\u00e9\n".encode("latin-1") + cube_obj(0, 0).encode())
    return ["contacts", str(path)]


def self_relation(text: str) -> str:
    return text.replace("[against, block.bottom, table.top]", "[against, block.bottom, block.bore]")


def feature(line: str) -> str:
    return TASK.replace("{type: hole, point: [0, 0, 1], axis: [0, 0, -1], radius: 0.2}", line)


COMPAS_MESH = {
    "dtype": "compas.datastructures/Mesh",
    "data": {
        "vertex": {
            str(i): dict(zip("xyz", v, strict=True))
            for i, v in enumerate([(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)])
        },
        "face": {"0": [0, 2, 1], "1": [0, 1, 3], "2": [0, 3, 2], "3": [1, 2, 3]},
    },
}
COMPAS_ASSEMBLY = {
    "dtype": "compas_assembly.datastructures/Assembly",
    "data": {"attributes": {}},
}
COMPAS_TYPO = [dict(COMPAS_MESH, dtype="compas.datastructures/Mseh")]

TOLERANCES = [
    ("1e300", "--tolerance"),
    ("-1", "--tolerance"),
    ("abc", "--tolerance"),
    ("0", "--tolerance"),
]

CASES: list[Case] = [
    # valid inputs: exit 0
    Case("solve ok", on("solve", "t.yaml", TASK), None),
    Case("solve rapt ok", on("solve", "t.rapt", RAPT), None),
    Case("contacts ok", on_assembly("contacts", "--png", "@c.png"), None, ("c.png",)),
    Case("motion ok", on_assembly("motion"), None),
    Case("blocking ok", on_assembly("blocking"), None),
    Case("mate ok", on("mate", "p.yaml", PROBLEM), None),
    Case(
        "plan ok",
        on_assembly("plan", "--png", "@p.png", "--html", "@p.html"),
        None,
        ("p.png", "p.html"),
    ),
    Case("blocking polygons ok", on("blocking", "g.yaml", POLYGONS), None),
    Case("contacts latin-1 mesh comment ok", latin1_comment_obj, None),
    # files that are not UTF-8, in every loader
    *[Case(f"solve {k}", on("solve", "t.yaml", v), "t.yaml") for k, v in NOT_UTF8.items()],
    *[Case(f"solve rapt {k}", on("solve", "t.rapt", v), "t.rapt") for k, v in NOT_UTF8.items()],
    Case("solve json latin1", on("solve", "t.json", NOT_UTF8["latin1"]), "t.json"),
    *[Case(f"mate {k}", on("mate", "p.yaml", v), "p.yaml") for k, v in NOT_UTF8.items()],
    *[Case(f"contacts {k}", on("contacts", "m.yaml", v), "m.yaml") for k, v in NOT_UTF8.items()],
    *[Case(f"blocking {k}", on("blocking", "m.yaml", v), "m.yaml") for k, v in NOT_UTF8.items()],
    Case("plan compas utf16", on("plan", "c.json", NOT_UTF8["utf16"]), "c.json"),
    Case("motion task latin1", on("motion", "t.yaml", NOT_UTF8["latin1"]), "t.yaml"),
    Case("motion config binary", on_folder(NOT_UTF8["binary"]), "config.json"),
    # deep nesting and alias bombs
    *[Case(f"{c} bomb", on(c, "x.yaml", BOMB), "x.yaml") for c in ("solve", "mate", "blocking")],
    *[Case(f"{c} deep", on(c, "x.yaml", DEEP), "x.yaml") for c in ("solve", "mate", "contacts")],
    Case("solve deep block", on("solve", "x.yaml", DEEP_BLOCK), "x.yaml"),
    Case("solve deep json", on("solve", "x.json", "[" * 100_000 + "]" * 100_000), "x.json"),
    # NaN / infinite numbers and flat parts
    Case("contacts nan vertex", on_assembly("contacts", b_obj=cube_obj(0, 1, "nan")), "b.obj"),
    Case("plan inf vertex", on_assembly("plan", b_obj=cube_obj(0, 1, "inf")), "b.obj"),
    Case("plan flat part", on_assembly("plan", b_obj=FLAT_OBJ), "b.obj"),
    Case("blocking huge vertex", on_assembly("blocking", b_obj=cube_obj(0, 1, "1e20")), "b.obj"),
    Case(
        "contacts face out of range",
        on_assembly("contacts", b_obj=cube_obj(0, 1) + "f 1 2 99\n"),
        "b.obj",
    ),
    Case(
        "solve feature type list",
        on("solve", "t.yaml", feature("{type: [hole], point: [0, 0, 1]}")),
        "bore",
    ),
    Case(
        "motion nan pose",
        on_assembly("motion", text=manifest("{translation: [0, .nan, 1]}")),
        "parts[1].pose",
    ),
    Case(
        "contacts inf matrix",
        on_assembly("contacts", text=manifest("[[1,0,0,.inf],[0,1,0,0],[0,0,1,1],[0,0,0,1]]")),
        "parts[1].pose",
    ),
    Case(
        "motion nan final_state",
        on_folder('{"b": {"final_state": [0, 0, 1, 0, 0, NaN]}}'),
        "b.final_state",
    ),
    Case(
        "contacts null part name",
        on_assembly("contacts", text=manifest().replace("name: b", "name: null")),
        "parts[1].name",
    ),
    Case(
        "plan overflowing translation",
        on_assembly("plan", text=manifest("{translation: [0, -1.0e+308, 1]}")),
        "parts[1].pose.translation",
    ),
    Case(
        "motion overflowing final_state",
        on_folder('{"b": {"final_state": [0, 0, 1e300, 0, 0, 0]}}'),
        "b.final_state",
    ),
    Case(
        "motion inf final_state",
        on_folder('{"b": {"final_state": [0, 0, Infinity, 0, 0, 0]}}'),
        "b.final_state",
    ),
    # relations and features
    Case("solve self relation", on("solve", "t.yaml", self_relation(TASK)), "itself"),
    Case(
        "solve rapt self relation",
        on("solve", "t.rapt", RAPT.replace("top of table", "bottom of block")),
        "itself",
    ),
    Case("motion self relation", on("motion", "t.yaml", self_relation(TASK)), "itself"),
    Case(
        "solve bool point",
        on(
            "solve",
            "t.yaml",
            feature("{type: hole, point: [true, 0, 1], axis: [0, 0, -1], radius: 0.2}"),
        ),
        "bore",
    ),
    Case(
        "solve nested point",
        on(
            "solve",
            "t.yaml",
            feature("{type: hole, point: [[0, 0, 1]], axis: [0, 0, -1], radius: 0.2}"),
        ),
        "bore",
    ),
    Case(
        "solve huge radius",
        on(
            "solve",
            "t.yaml",
            feature("{type: hole, point: [0, 0, 1], axis: [0, 0, -1], radius: 1e308}"),
        ),
        "bore",
    ),
    Case(
        "solve huge axis",
        on(
            "solve",
            "t.yaml",
            feature("{type: hole, point: [0, 0, 1], axis: [1e300, 1e300, 1e300], radius: 1}"),
        ),
        "bore",
    ),
    Case(
        "mate bool point",
        on(
            "mate",
            "p.yaml",
            PROBLEM.replace(
                "point: [0, 0, 0], axis: [0, 0, -1], radius: 2}",
                "point: [0, false, 0], axis: [0, 0, -1], radius: 2}",
                1,
            ),
        ),
        "socket",
    ),
    Case(
        "mate self goal",
        on("mate", "p.yaml", PROBLEM.replace("[fit, p2, base]", "[fit, p2, p2]")),
        "p.yaml",
    ),
    Case(
        "blocking polygon nan",
        on("blocking", "g.yaml", POLYGONS.replace("[2, 2]", "[.nan, 2]")),
        "parts.b",
    ),
    Case(
        "blocking polygon bool",
        on("blocking", "g.yaml", POLYGONS.replace("[2, 2]", "[true, 2]")),
        "parts.b",
    ),
    Case(
        "blocking polygon ragged",
        on("blocking", "g.yaml", POLYGONS.replace("[2, 2]", "[2]")),
        "parts.b",
    ),
    Case("blocking polygons none", on("blocking", "g.yaml", "parts: {}\n"), "g.yaml"),
    Case(
        "plan polygon far",
        on("plan", "g.yaml", POLYGONS.replace("[2, 2]", "[2, 1.0e300]")),
        "coordinates beyond",
    ),
    Case(
        "solve relation option number",
        on(
            "solve",
            "t.yaml",
            TASK.replace(
                "[against, block.bottom, table.top]", "[against, block.bottom, table.top, {5: 1}]"
            ),
        ),
        "no option 5",
    ),
    Case("demo out in a symbolic link loop", lambda folder: _loop(folder, "demo"), "--out"),
    # usage errors are one line too, naming the help to read
    Case("plan unknown option", on_assembly("plan", "--nosuch"), "'assemblykit plan --help'"),
    Case("no such command", lambda folder: ["nosuch"], "'assemblykit --help'"),
    # integers beyond a float, and beyond what Python converts (4,300 digits)
    Case(
        "blocking polygon huge",
        on("blocking", "g.yaml", POLYGONS.replace("[2, 2]", f"[{10**400}, 2]")),
        "g.yaml",
    ),
    Case(
        "solve task huge radius",
        on("solve", "t.yaml", TASK.replace("radius: 0.2", f"radius: {10**400}")),
        "t.yaml",
    ),
    Case(
        "solve task long radius",
        on("solve", "t.yaml", TASK.replace("radius: 0.2", "radius: " + "9" * 5000)),
        "t.yaml",
    ),
    Case(
        "solve rapt huge point",
        on(
            "solve",
            "t.rapt",
            RAPT.replace(
                "point (0, 0, 0) normal (0, 0, -1)", f"point (0, 0, {10**400}) normal (0, 0, -1)"
            ),
        ),
        "t.rapt",
    ),
    Case(
        "solve rapt long point",
        on(
            "solve",
            "t.rapt",
            RAPT.replace(
                "point (0, 0, 0) normal (0, 0, -1)",
                "point (0, 0, " + "9" * 5000 + ") normal (0, 0, -1)",
            ),
        ),
        "line 6",
    ),
    Case(
        "plan manifest huge pose",
        on_assembly("plan", text=manifest(f"{{translation: [0, 0, {10**400}]}}")),
        "asm.yaml",
    ),
    Case(
        "contacts json long number",
        on("contacts", "c.json", '{"a": ' + "9" * 5000 + "}"),
        "c.json",
    ),
    *(
        Case(
            f"batch timeout {value}",
            lambda folder, value=value: ["batch", str(write_assembly(folder)), "--timeout", value],
            "--timeout",
        )
        for value in ("0", "-1", "nan", "inf")
    ),
    # COMPAS documents
    Case(
        "contacts compas no graph", on("contacts", "c.json", json.dumps(COMPAS_ASSEMBLY)), "c.json"
    ),
    Case("blocking compas typo", on("blocking", "c.json", json.dumps(COMPAS_TYPO)), "Mseh"),
    Case(
        "contacts compas bool",
        on(
            "contacts",
            "c.json",
            json.dumps(
                [
                    {
                        **COMPAS_MESH,
                        "data": {
                            **COMPAS_MESH["data"],
                            "vertex": {"0": {"x": True, "y": 0, "z": 0}},
                        },
                    }
                ]
            ),
        ),
        "c.json",
    ),
    # options: tolerances
    *[
        Case(f"solve tolerance {t}", on("solve", "t.yaml", TASK, "--tolerance", t), o)
        for t, o in TOLERANCES
    ],
    *[
        Case(f"mate tolerance {t}", on("mate", "p.yaml", PROBLEM, "--tolerance", t), o)
        for t, o in TOLERANCES[:2]
    ],
    *[
        Case(f"{c} tolerance {t}", on_assembly(c, "--tolerance", t), o)
        for c in ("contacts", "motion", "blocking", "plan")
        for t, o in TOLERANCES[::2]
    ],
    # options: output paths
    Case("plan png folder", on_assembly("plan", "--png", "@"), "--png"),
    Case("plan png folder named .png", on_assembly("plan", "--png", "@d.png/"), "is a folder"),
    Case("plan png missing folder", on_assembly("plan", "--png", "@no/x.png"), "--png"),
    Case("plan png extension", on_assembly("plan", "--png", "@x.gif"), "--png"),
    Case("plan png no extension", on_assembly("plan", "--png", "@x"), "/x: --png"),
    Case("plan png symlink", on_link("plan", "--png", "p.png"), "symbolic link"),
    Case("plan html symlink", on_link("plan", "--html", "p.html"), "symbolic link"),
    Case("contacts png symlink", on_link("contacts", "--png", "c.png"), "symbolic link"),
    Case("blocking png dangling symlink", on_link("blocking", "--png", "b.png", True), "--png"),
    Case("motion html symlink", on_link("motion", "--html", "m.html"), "symbolic link"),
    Case("batch out symlink", on_link("batch", "--out", "r.jsonl"), "symbolic link"),
    Case("plan html under a file", on_assembly("plan", "--html", "@a.obj/x.html"), "--html"),
    Case("plan html folder", on_assembly("plan", "--html", "@"), "--html"),
    Case("contacts png missing folder", on_assembly("contacts", "--png", "@no/c.png"), "--png"),
    Case("contacts png folder", on_assembly("contacts", "--png", "@"), "--png"),
    Case("blocking png extension", on_assembly("blocking", "--png", "@b.pdf"), "--png"),
    Case("motion html missing folder", on_assembly("motion", "--html", "@no/m.html"), "--html"),
    Case("motion html extension", on_assembly("motion", "--html", "@m.png"), "--html"),
    Case(
        "demo out is a file", lambda folder: ["demo", "--out", str(write_assembly(folder))], "--out"
    ),
    Case("demo tolerance", lambda folder: ["demo", "--tolerance", "1e300"], "--tolerance"),
    # batch: checked before any child runs
    Case("batch out folder", on_assembly("batch", "--out", "@"), "--out"),
    Case("batch out missing folder", on_assembly("batch", "--out", "@no/r.jsonl"), "--out"),
    Case("batch tolerance", on_assembly("batch", "--tolerance", "abc"), "--tolerance"),
    Case(
        "batch results latin1",
        lambda folder: [
            "batch",
            str(write_assembly(folder)),
            "--out",
            str(_file("r.jsonl", NOT_UTF8["latin1"])(folder)),
        ],
        "r.jsonl",
        ("r.jsonl",),
    ),
    Case(
        "batch results garbage",
        lambda folder: [
            "batch",
            str(write_assembly(folder)),
            "--out",
            str(_file("r.jsonl", "5\n{}\n")(folder)),
        ],
        "r.jsonl",
        ("r.jsonl",),
    ),
]


def run(argv: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    """Exit code, stdout and stderr of the command line run in-process."""
    try:
        main(argv)
        code = 0
    except SystemExit as done:
        code = done.code if isinstance(done.code, int) else 1
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def files(folder: Path) -> dict[str, float]:
    return {str(p.relative_to(folder)): p.stat().st_mtime for p in folder.rglob("*") if p.is_file()}


@pytest.mark.parametrize("case", CASES, ids=[c.name for c in CASES])
def test_bad_input_is_refused_in_one_line(
    case: Case, tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    argv = case.build(tmp_path)
    before = files(tmp_path)
    code, _, err = run(argv, capsys)
    after = files(tmp_path)
    written = {name for name in after if before.get(name) != after[name]}
    assert written <= set(case.outputs), f"wrote {written - set(case.outputs)}"
    if case.names is None:
        assert code == 0, err
        return
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert case.names in lines[0] and "internal error" not in lines[0], err


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into read-only folders")
def test_output_in_a_read_only_folder_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o500)
    try:
        code, _, err = run(on_assembly("contacts", "--png", "@locked/c.png")(tmp_path), capsys)
    finally:
        locked.chmod(0o700)
    assert code == 2 and "--png" in err and "permission" in err


def test_png_message_names_the_file_written(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # the suffix is the writer's (any case); the file is written under exactly that name
    code, _, err = run(on_assembly("plan", "--png", "@view.PNG")(tmp_path), capsys)
    assert code == 0, err
    assert err.strip() == f"wrote {tmp_path / 'view.PNG'}"
    assert (tmp_path / "view.PNG").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert not (tmp_path / "view.PNG.png").exists()


def test_a_failed_write_leaves_nothing_behind(tmp_path: Path) -> None:
    target = tmp_path / "out.png"
    with pytest.raises(RuntimeError), atomic_output(target) as temporary:
        temporary.write_bytes(b"half")
        raise RuntimeError("drawing failed")
    assert list(tmp_path.iterdir()) == []
    with atomic_output(target) as temporary:
        temporary.write_bytes(b"whole")
    assert [p.name for p in tmp_path.iterdir()] == ["out.png"]
    assert target.read_bytes() == b"whole"


def test_loaders_raise_assemblykit_errors(tmp_path: Path) -> None:
    """The library's loaders raise :class:`InputError` subclasses, never bare builtins."""
    bad = tmp_path / "bad.yaml"
    bad.write_bytes(NOT_UTF8["latin1"])
    for loader in (load_task, load_problem, load_manifest, load_compas):
        with pytest.raises(InputError, match=re.escape("bad.yaml")):
            loader(bad)
    (tmp_path / "x.obj").write_text(cube_obj(0, 0))
    (tmp_path / "config.json").write_bytes(NOT_UTF8["utf16"])
    with pytest.raises(InputError, match=re.escape("config.json")):
        load_mesh_folder(tmp_path)
    with pytest.raises(InputError, match=re.escape("missing")):
        load_mesh_folder(tmp_path / "missing")
    with pytest.raises(InputError, match=f"deeper than {MAX_DEPTH}"):
        read_yaml("[" * (MAX_DEPTH + 1) + "]" * (MAX_DEPTH + 1), "x.yaml")


BUNDLED = [
    ("solve", EXAMPLES / "tasks" / "peg_in_block.yaml"),
    ("solve", EXAMPLES / "tasks" / "peg_in_block.rapt"),
    ("motion", EXAMPLES / "tasks" / "four_bar.yaml"),
    ("mate", EXAMPLES / "mating" / "one_socket.yaml"),
    ("mate", EXAMPLES / "mating" / "shaft_fit.yaml"),
    ("blocking", EXAMPLES / "planar" / "hook.yaml"),
]


@settings(
    max_examples=60,
    deadline=None,
    database=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture],
)
@given(
    which=st.sampled_from(range(len(BUNDLED))),
    cut=st.floats(0, 1),
    at=st.floats(0, 1),
    insert=st.sampled_from(
        [
            "",
            "\x00",
            "[",
            "]",
            "{",
            ":",
            "- ",
            "&a ",
            "*a",
            "\n  ",
            "nan",
            "1e999",
            "true",
            ",",
            "é",
            "\t",
        ]
    ),
)
def test_mutated_bundled_files_never_crash(
    which: int,
    cut: float,
    at: float,
    insert: str,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """Truncated or mutated bundled files are answered (exit 0) or refused (exit 2)."""
    command, source = BUNDLED[which]
    text = source.read_text()
    keep = int(len(text) * max(cut, 0.5 if insert else 0.0))
    place = int(keep * at)
    mutated = text[:place] + insert + text[place:keep]
    path = tmp_path / f"mutated{source.suffix}"
    path.write_text(mutated)
    code, _, err = run([command, str(path)], capsys)
    assert code in (0, 2), err
    if code == 2:
        assert len(err.strip().splitlines()) == 1 and "mutated" in err, err


def test_input_errors_are_assemblykit_errors() -> None:
    assert issubclass(InputError, AssemblyKitError)
