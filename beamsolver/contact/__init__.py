"""Beam-to-beam contact: kinematics of the seed paper (SE(3) slip increment)."""
from .kinematics import slip_increment, relative_motion

__all__ = ["slip_increment", "relative_motion"]
