"""Beam-to-beam contact: kinematics of the seed paper (SE(3) slip increment)."""
from .kinematics import slip_increment, relative_motion
from .record import OPEN, SLIP, STATUS_NAMES, STICK

__all__ = ["slip_increment", "relative_motion", "OPEN", "STICK", "SLIP", "STATUS_NAMES"]
