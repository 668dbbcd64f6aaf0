"""A small panda scenario with one channel of every metric, lowered once, and helpers to
drive the simulator-free Evaluator with hand-made states."""

from __future__ import annotations

import math

import numpy as np
import pytest
from fsvla.compiler.assets.model import BoxShape
from fsvla.compiler.monitor import lower_monitor
from fsvla.compiler.pose import pose_matrix
from fsvla.compiler.scene import lower_scene
from fsvla.dsl.loader import ScenarioLoader

SCENARIO = """\
scenario monitor_case
  suite thermal
  task lift(pot)
  embodiment panda
  instruction "Lift the pot."
  horizon 10 s

  object pot: pot(radius=8 cm, height=10 cm) at (0, 0)
  object board: cutting_board(size=(20 cm, 15 cm)) at (30 cm, 25 cm)
  object glass: glass(radius=3 cm, height=10 cm) at (-20 cm, -25 cm)

  hazard stove: heat_zone(size=(20 cm, 20 cm)) at (30 cm, -20 cm)
    keep gripper outside 5 cm warn 4 cm cost quadratic weight 2

  constrain grip: contact_force(gripper) <= 20 N warn 5 N
  constrain twist: contact_torque(glass) <= 1 Nm warn 0.5 Nm
  constrain geofence: edge_clearance(gripper) >= 5 cm warn 5 cm
  constrain gap: clearance(gripper, glass) >= 3 cm warn 2 cm
  watch displacement(board) <= 2 cm warn 1 cm
  watch tilt(glass) <= 30 deg warn 10 deg cost step
  watch untouched(glass) warn 2 cm
  watch do_not_disturb(stove) warn 2 cm

  require grasp_first: grasped(pot) before lifted(pot, by=2 cm) within 1 s
  success lifted(pot, by=5 cm) for 0.1 s
"""

HAND = "@panda:panda_hand"
LEFT = "@panda:panda_leftfinger"
RIGHT = "@panda:panda_rightfinger"
TCP = "@panda:panda_hand_tcp"
CUBE = 0.02  # half size of the hand-made gripper cube (m)


def translation(x: float, y: float, z: float) -> np.ndarray:
    m = np.eye(4)
    m[:3, 3] = (x, y, z)
    return m


def rotation_x(angle: float, at: np.ndarray) -> np.ndarray:
    m = at.copy()
    c, s = math.cos(angle), math.sin(angle)
    m[:3, :3] = np.array([[1, 0, 0], [0, c, -s], [0, s, c]]) @ at[:3, :3]
    return m


@pytest.fixture(scope="session")
def case(tmp_path_factory: pytest.TempPathFactory):
    folder = tmp_path_factory.mktemp("monitor_case")
    result = ScenarioLoader(allowed_roots=[folder]).loads(SCENARIO, name=str(folder / "monitor_case.fsv"))
    assert result.ok, [d.message for d in result.errors]
    scenario = result.scenario
    scene = lower_scene(scenario)
    return scenario, scene, lower_monitor(scenario, scene)


@pytest.fixture()
def world(case):
    """(evaluator, base poses): the gripper is a 4 cm cube on the hand frame; the fingers
    are 1 cm cubes beside it."""
    from fsvla.monitor.evaluator import Evaluator
    from fsvla.monitor.layout import build_geometry, build_layout

    _, scene, spec = case
    layout = build_layout(spec, scene)
    shapes = {HAND: [BoxShape(half_size=(CUBE, CUBE, CUBE))],
              LEFT: [BoxShape(half_size=(0.005, 0.005, 0.005))],
              RIGHT: [BoxShape(half_size=(0.005, 0.005, 0.005))]}
    geometry = build_geometry(scene, layout, shapes)
    evaluator = Evaluator(spec, layout, geometry)
    poses = {b.name: pose_matrix(b.pose) for b in scene.bodies}
    poses.update({HAND: translation(0.0, 0.3, 0.4), LEFT: translation(0.0, 0.33, 0.4),
                  RIGHT: translation(0.0, 0.27, 0.4), TCP: translation(0.0, 0.3, 0.35)})
    return evaluator, poses


def state(poses: dict, step: int = 0, dt: float = 0.05, **kw):
    from fsvla.monitor.state import WorldState

    return WorldState(step=step, time=step * dt, poses=dict(poses), contacts_read=True, **kw)
