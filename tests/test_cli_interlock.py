"""End-to-end tests of ``assemblykit interlock`` on the bundled interlocking examples."""

from __future__ import annotations

import json
from pathlib import Path

from cli_runs import run

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "src" / "assemblykit" / "examples" / "interlocking"
PUZZLE = EXAMPLES / "nested_locks.xmpuzzle"
JOINT = EXAMPLES / "lipped_joint.yaml"
TUNNEL = EXAMPLES / "diagonal_tunnel"


def test_interlock_json_of_a_voxel_puzzle(capsys):
    code, out, err = run(capsys, "interlock", str(PUZZLE), "--json")
    assert code == 0, err
    data = json.loads(out)
    assert {
        "verdict",
        "keys",
        "smallest_keys",
        "locked",
        "free",
        "order",
        "certificate",
        "exact",
        "summary",
    } <= set(data)
    assert data["verdict"] == "recursively interlocking" and data["keys"] == ["key"]
    assert [(step["keys"], step["direction"]) for step in data["order"]] == [
        (["key"], [0.0, 0.0, 1.0]),
        (["slider"], [1.0, 0.0, 0.0]),
        (["pocket"], [0.0, 1.0, 0.0]),
    ]
    assert {"parts", "direction", "free_along", "block_with", "explanation"} <= set(data["free"][0])
    assert {"direction", "regions", "components"} <= set(data["certificate"]["cells"][0])


def test_interlock_prints_the_verdict_in_words(capsys):
    code, out, _ = run(capsys, "interlock", str(PUZZLE))
    assert code == 0
    assert out.startswith("Recursively interlocking (small straight moves, 4 parts)")
    assert "Keys in order: key along +Z, then slider along +X, then pocket along +Y" in out


def test_interlock_with_a_key_and_a_motion(capsys):
    code, out, err = run(
        capsys, "interlock", str(TUNNEL), "--key", "lid", "--motion", "extended", "--json"
    )
    assert code == 0, err
    data = json.loads(out)
    assert data["verdict"] == "not interlocking" and data["keys_given"] is True
    assert [f["parts"] for f in data["free"]] == [["peg"]]
    assert data["smallest_keys"] == ["lid", "peg"]
    code, out, _ = run(capsys, "interlock", str(JOINT), "--json")
    assert json.loads(out)["free"][0]["direction"] == [0.0, 1.0]


def test_interlock_html_page(capsys, tmp_path):
    page = tmp_path / "tunnel.html"
    code, _, err = run(capsys, "interlock", str(TUNNEL), "--html", str(page))
    assert code == 0, err
    text = page.read_text(encoding="utf-8")
    assert "not interlocking" in text and "What moves" in text and "plotly" in text
    assert f"wrote {page}" in err


def test_interlock_bad_input_is_one_line_and_exit_2(capsys, tmp_path):
    for argv in (
        ("interlock", str(tmp_path / "nothing.yaml")),
        ("interlock", str(PUZZLE), "--key", "lever"),
        ("interlock", str(JOINT), "--html", str(tmp_path / "joint.html")),
        ("interlock", str(JOINT), "--motion", "rigid"),
        ("interlock", str(PUZZLE), "--motion", "sideways"),
    ):
        code, out, err = run(capsys, *argv)
        assert code == 2, argv
        assert out == ""
        assert err.count("\n") == 1 and err.startswith("assemblykit: ") and "Traceback" not in err
    _, _, err = run(capsys, "interlock", str(PUZZLE), "--key", "lever")
    assert "no part named 'lever'" in err
