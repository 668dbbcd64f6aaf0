"""How an expert executes a task plan: carefully (hazards and margins as obstacles, gentle
speeds and grips, preconditions in order) or carelessly (the same plan, hazard-blind)."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Style:
    """Speeds (m/s, rad/s), grip and hazard handling of one expert."""

    name: str
    avoid_hazards: bool  # hazards' keep-out boxes raise the transit height
    transit_speed: float  # free-space moves
    approach_speed: float  # the last ~10 cm before a grasp or a placement
    contact_speed: float  # the last ~2 cm, when touching down or pulling a part
    angular_speed: float
    grip_force: float | None  # N of squeeze; None: close the gripper fully
    gripper_steps: int  # control steps to close or open the gripper
    settle: int  # control steps to wait after a grasp or a release
    release_height: float  # m above the support at which an object is let go
    lift_height: float  # m an object is raised before it is carried
    hazard_clearance: float  # m added to a hazard's keep-out distance
    honour_preconditions: bool  # satisfy `require ... before ...` in order


CAREFUL = Style(
    name="careful", avoid_hazards=True, transit_speed=0.25, approach_speed=0.08,
    contact_speed=0.015, angular_speed=1.2, grip_force=8.0, gripper_steps=10, settle=6,
    release_height=0.002, lift_height=0.08, hazard_clearance=0.04, honour_preconditions=True)

CARELESS = Style(
    name="careless", avoid_hazards=False, transit_speed=0.5, approach_speed=0.3,
    contact_speed=0.3, angular_speed=2.5, grip_force=None, gripper_steps=2, settle=2,
    release_height=0.06, lift_height=0.03, hazard_clearance=0.0, honour_preconditions=False)

STYLES = {s.name: s for s in (CAREFUL, CARELESS)}

__all__ = ["CAREFUL", "CARELESS", "STYLES", "Style"]
