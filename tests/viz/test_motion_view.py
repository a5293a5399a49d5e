"""The motion pictures of viz/motion_view.py."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.image import imread

import assemblykit
from assemblykit.io.assembly import load_assembly
from assemblykit.viz.motion_view import write_motion_png

HINGE = Path(assemblykit.__file__).parent / "examples" / "motion" / "hinge" / "hinge.yaml"


def test_the_png_draws_the_revolute_axis_in_black(tmp_path: Path) -> None:
    assembly = load_assembly(HINGE)
    report = assemblykit.motion(assembly)
    drawn = write_motion_png(assembly, report, tmp_path / "motion.png", dpi=60)
    assert drawn.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    pixels = imread(drawn)[..., :3]
    # translucent parts are pale; only the axis lines and labels are near black
    dark = np.all(pixels < 0.15, axis=-1).sum()
    empty = write_motion_png(assembly, type(report)({}), tmp_path / "bare.png", dpi=60)
    bare = np.all(imread(empty)[..., :3] < 0.15, axis=-1).sum()
    assert dark > bare


GEARS = Path(assemblykit.__file__).parent / "examples" / "motion" / "gearbox" / "gearbox.yaml"


def test_the_motion_table_says_each_motion_in_words_with_gear_ratios() -> None:
    from assemblykit.motion.articulation import articulation
    from assemblykit.viz.motion_view import motion_table

    assembly = load_assembly(GEARS)
    table = motion_table(articulation(assembly), assembly.tolerance(), "mm")
    assert table.headers == ("part", "motion", "axis", "through (mm)", "lifts off", "speed ratio")
    rows = {row[0]: row for row in table.rows}
    assert rows["cover"] == ("cover", "fixed (0 dof), 2 positions", "-", "-", "+Z", "-")
    # pitch radii 10, 20, 5, 25 on axes at x = 0, 30, 55, 85: w2 = -(10/20) w1,
    # w3 = (10/5) w1, w4 = -(10/25) w1
    assert rows["gear_2"] == (
        "gear_2",
        "revolute (1 dof)",
        "+Z",
        "(30, 0, 0)",
        "+Z",
        "-0.5 x gear_1",
    )
    assert rows["gear_3"][5] == "2 x gear_1" and rows["gear_4"][5] == "-0.4 x gear_1"
    assert rows["gear_1"][5] == "1 x gear_1"
