"""Policies fsvla evaluates: the interface, the built-ins, and loading ``--policy`` values."""

from .base import ActionSchema, CameraSchema, EpisodeInfo, ObservationSchema, Policy
from .registry import BUILTIN, PolicyLoadError, load_policy
from .simple import HoldStillPolicy, RandomPolicy

__all__ = ["BUILTIN", "ActionSchema", "CameraSchema", "EpisodeInfo", "HoldStillPolicy",
           "ObservationSchema", "Policy", "PolicyLoadError", "RandomPolicy", "load_policy"]
