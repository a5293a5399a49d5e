"""Oriented primitive features, their pairwise relationships and compound features
(Liu 1997 §2-§3, docs/algebra.md §4)."""

from assemblykit.features.compound import (
    CompoundFeature,
    Relationship,
    compound_group,
    relationship,
)
from assemblykit.features.primitives import (
    Axis,
    Ball,
    Cone,
    Feature,
    Frame,
    Hole,
    Plane,
    Point,
    Prism,
    Shaft,
    Socket,
    Thread,
    Torus,
    feature_from_dict,
    parse_angle,
)

__all__ = [
    "Axis",
    "Ball",
    "CompoundFeature",
    "Cone",
    "Feature",
    "Frame",
    "Hole",
    "Plane",
    "Point",
    "Prism",
    "Relationship",
    "Shaft",
    "Socket",
    "Thread",
    "Torus",
    "compound_group",
    "feature_from_dict",
    "parse_angle",
    "relationship",
]
