"""Mating inference (seed 002): problems, the two-layer graph, the laws and the search."""
