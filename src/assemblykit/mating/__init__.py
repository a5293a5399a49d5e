"""Mating inference (Liu & Popplestone 1990): problems, the two-layer graph, the laws and the
search."""
