"""Demonstrations: the careful expert's safe successes as a LeRobot dataset (`fsvla collect`)."""

from .collect import PROGRESS_FILE, CollectProgress, collect
from .lerobot import CODEBASE_VERSION, DatasetMismatch, Frame, LeRobotWriter, features

__all__ = ["CODEBASE_VERSION", "PROGRESS_FILE", "CollectProgress", "DatasetMismatch", "Frame",
           "LeRobotWriter", "collect", "features"]
