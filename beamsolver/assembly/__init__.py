"""DOF numbering, constraints, sparsity pattern and the scatter of element and contact blocks."""
