"""Robot embodiments as data: specs, the built-in TOML files and their loader.

Nothing here imports a simulator; ``fsvla.sim.robot`` loads a spec into SAPIEN.
"""

from .registry import UnknownEmbodimentError, builtin_embodiments, load_embodiment
from .spec import (
    ArmSpec,
    CameraSpec,
    DriveSpec,
    EmbodimentSpec,
    GripperSpec,
    MountSpec,
    RobotSpec,
    WorkspaceSpec,
)

__all__ = [
    "ArmSpec", "CameraSpec", "DriveSpec", "EmbodimentSpec", "GripperSpec", "MountSpec",
    "RobotSpec", "UnknownEmbodimentError", "WorkspaceSpec", "builtin_embodiments",
    "load_embodiment",
]
