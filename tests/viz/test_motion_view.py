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
