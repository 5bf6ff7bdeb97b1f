"""The Problem interface, linear solvers, definiteness and modes of the tangent."""
