"""Command line, parameter sweeps and studies, pictures."""
