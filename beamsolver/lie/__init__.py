"""Lie groups SE(3)/SO(3): batched numpy maps and their compiled scalar kernels."""
