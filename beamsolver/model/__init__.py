"""What the user declares: Model, sections, geometry, cables, motions, loads, contributions, checks."""
