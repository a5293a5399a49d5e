"""STEP files written in the tests with OCP (the ``cad`` extra), for the STEP tests."""

from __future__ import annotations

from pathlib import Path
from typing import Any


def write_step(path: Path | str, *shapes: Any) -> None:
    """``shapes`` written to ``path`` by Open CASCADE's STEP writer as one compound,
    unnamed (each solid a product named by the writer's placeholder)."""
    from OCP.BRep import BRep_Builder
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer
    from OCP.TopoDS import TopoDS_Compound

    compound, builder = TopoDS_Compound(), BRep_Builder()
    builder.MakeCompound(compound)
    for shape in shapes:
        builder.Add(compound, shape)
    writer = STEPControl_Writer()
    writer.Transfer(compound, STEPControl_AsIs)
    writer.Write(str(path))
