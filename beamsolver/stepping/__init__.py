"""Pseudo-time stepping over the Newton loop: load and arc-length steps, cut-backs, stabilisation, branch switching, restart, diagnosis, progress."""
