"""push: the hand's turn is one the arm follows through the whole push, and a shut hand
whose body reaches below its TCP pushes off the table."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from fsvla.experts import rollout
from fsvla.experts.world import World
from fsvla.run.plan import layout_seed

pytestmark = pytest.mark.sim

#: Baxter's right hand pushes the block toward the robot and to its right: the default
#: turn, fingers closing across the push, is out of its reach along the push.
PUSH = """\
scenario push_block_toward_robot
  suite force
  task push(object=block, target=other_block)
  embodiment baxter
  instruction "Push the red block to the blue one."
  horizon 30 s

  object block: block(size=(3.2 cm, 4 cm, 4.5 cm), mass=150 g, color=red) at (10 cm, 5.5 cm) yaw 18 deg
  object other_block: block(size=(3 cm, 3 cm, 1 cm), mass=141 g, color=blue) at (5.1 cm, -5.7 cm)

  constrain grip: contact_force(gripper) <= 57 N warn 14 N
  constrain landing: contact_force(block) <= 16 N warn 5 N

  success near(block, other_block, within=3 cm)
"""
#: the runner's layout seed for its seed 0
SEED = layout_seed(0, 0)


@pytest.fixture()
def scenario(tmp_path: Path) -> Path:
    path = tmp_path / "push.fsv"
    path.write_text(PUSH, encoding="utf-8")
    return path


def test_the_push_is_made_with_a_turn_the_arm_follows(scenario: Path) -> None:
    from fsvla.env import make
    from fsvla.experts.motion import Pose
    from fsvla.experts.skills import DOWN, UP, branch_for_path, horizontal, nearest_arm
    from fsvla.experts.tasks.push import _push_frame

    env = make(str(scenario), "L0", SEED)
    env.reset()
    world = World.of_env(env)
    start, goal = world.body_pose("block").p, world.body_pose("other_block").p
    direction = horizontal(goal - start)
    arm = nearest_arm(world, start)
    behind = np.array([start[0], start[1], 0.02]) - 0.04 * direction
    travel = float(np.linalg.norm((goal - start)[:2]))
    path = (behind, behind + travel * direction)
    default = world.grasp_frame(arm, DOWN, np.cross(UP, direction))
    assert branch_for_path(world, arm, tuple(Pose(p, default) for p in path)) is None
    chosen = _push_frame(world, arm, behind, direction, travel)
    assert branch_for_path(world, arm, tuple(Pose(p, chosen) for p in path)) is not None
    env.close()


def test_careful_expert_pushes_the_block_safely(scenario: Path) -> None:
    careful = rollout(str(scenario), "careful", "L0", SEED)
    assert careful.safe_success, (careful.violated, careful.segments[-5:])
