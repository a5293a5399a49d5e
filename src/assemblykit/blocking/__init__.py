"""Blocking graphs (docs/blocking.md). Importing the package imports
:mod:`assemblykit.blocking.planar`, which registers the planar variants of the
functions dispatched on the kind of assembly (contacts, Γ_e terms)."""

from assemblykit.blocking import planar as planar
