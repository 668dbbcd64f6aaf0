"""What an embodiment can do, measured on its model: reach and gripper opening.

The robot is loaded into a physics-only SAPIEN scene of its own (no table, nothing
stepped) and asked two things, through ``fsvla.sim``'s public pieces:

* **reach** — :meth:`RobotModel.reach_gap`: how far a point lies beyond what the arm's
  tool centre point (TCP) reaches. ``ArmKinematics.inverse`` (seeded, deterministic) is
  asked for the point with the gripper pointing straight down and tilted 30°, 60° and
  90° away from the arm's base and 30°, 60° toward it; the point is reached when one answer
  is within 1 cm and 0.05 rad, inside the joint limits. Otherwise the gap is the smallest
  position error of the answers (those within the joint limits, when there are any): the
  closest the TCP gets, which is how far beyond its reach the point lies.
* **opening** — :meth:`RobotModel.opening`: how far apart the fingers are at the TCP when
  the gripper is open, taking its ``closed`` position as fingers together: the points of
  the finger links that coincide with the TCP when closed are followed to the open
  position and their largest distance is the opening (a Panda hand: 8 cm; an SO-101 jaw
  swinging 1.15 rad: 8.7 cm).
* **shut gap** — :meth:`RobotModel.shut_gap`: how far apart the fingers' pads (their
  collision hulls within 3.5 cm behind the TCP) stay across the closing axis with the
  gripper shut: Baxter's fingertips stop 1.6 cm (left) and 0.7 cm (right) apart; a Panda's
  fingers and a hinged jaw meet.

Loading a robot takes 0.02-0.25 s; models are cached per embodiment.
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import lru_cache
from typing import Any

import numpy as np
from numpy.typing import NDArray

from fsvla.compiler.pose import matrix_to_quat, point_axis, quat_to_matrix
from fsvla.embodiments.spec import EmbodimentSpec

#: Approach directions tried, in degrees from straight down: positive tilts away from the
#: arm's base (toward the point), negative toward it.
APPROACH_TILTS = (0.0, 30.0, 60.0, 90.0, -30.0, -60.0)
POSITION_TOLERANCE = 0.01  # m
ROTATION_TOLERANCE = 0.05  # rad


class RobotModel:
    """One embodiment loaded into a scene of its own, at home."""

    def __init__(self, spec: EmbodimentSpec) -> None:
        import sapien

        from fsvla.sim.kinematics import ArmKinematics
        from fsvla.sim.robot import load_robot

        self.spec = spec
        self._scene = sapien.Scene([sapien.physx.PhysxCpuSystem()])
        self.robot = load_robot(self._scene, spec)
        self._kinematics = {name: ArmKinematics(arm) for name, arm in self.robot.arms.items()}
        self._openings: dict[str, float] = {}

    @property
    def arms(self) -> tuple[str, ...]:
        return tuple(self.robot.arms)

    def base(self, arm: str) -> NDArray[np.float64]:
        """The world position of the arm's base link."""
        return np.asarray(self.robot.arm(arm).base_link.entity_pose.p, dtype=np.float64)

    def reach_gap(self, arm: str, point: Sequence[float]) -> float:
        """0 when the arm's TCP reaches ``point`` (world, m), else how far beyond (module doc)."""
        ik = self._kinematics[arm]
        target = tuple(float(v) for v in point)
        answers = []
        for orientation in self._orientations(arm, np.asarray(target)):
            answer = ik.inverse(target, orientation)
            if answer.ok(POSITION_TOLERANCE, ROTATION_TOLERANCE):
                return 0.0
            answers.append(answer)
        within = [a for a in answers if a.within_limits] or answers
        return max(POSITION_TOLERANCE, min(a.position_error for a in within))

    def _orientations(self, arm: str, point: NDArray[np.float64]) -> list[Any]:
        ik = self._kinematics[arm]
        down = ik.top_down()
        outward = point - self.base(arm)
        outward[2] = 0.0
        norm = float(np.linalg.norm(outward))
        if norm < 1e-6:
            return [down]
        outward /= norm
        rotation = quat_to_matrix(down)
        axis = self.robot.arm(arm).spec.approach_axis
        found = []
        for tilt in np.deg2rad(APPROACH_TILTS):
            direction = np.cos(tilt) * np.array([0.0, 0.0, -1.0]) + np.sin(tilt) * outward
            found.append(down if tilt == 0.0 else
                         matrix_to_quat(point_axis(rotation, axis, tuple(direction.tolist()))))
        return found

    def opening(self, arm: str) -> float:
        """The gripper's opening at the TCP, in metres (module doc)."""
        if arm not in self._openings:
            self._openings[arm] = self._measure_opening(arm)
        return self._openings[arm]

    def shut_gap(self, arm: str) -> float:
        """How far apart (m) the fingers' pads stay with the gripper shut (module doc)."""
        from fsvla.experts.world import PAD_DEPTH

        return self._kinematics[arm].shut_gap(PAD_DEPTH)

    def _measure_opening(self, arm: str) -> float:
        points = self._kinematics[arm].finger_points(1.0)
        return max((float(np.linalg.norm(a - b)) for i, a in enumerate(points) for b in points[i + 1:]),
                   default=0.0)


@lru_cache(maxsize=8)
def _model(key: str) -> RobotModel:
    return RobotModel(EmbodimentSpec.model_validate_json(key))


def robot_model(spec: EmbodimentSpec) -> RobotModel:
    """The (cached) model of an embodiment."""
    return _model(spec.model_dump_json())


__all__ = ["APPROACH_TILTS", "POSITION_TOLERANCE", "ROTATION_TOLERANCE", "RobotModel", "robot_model"]
