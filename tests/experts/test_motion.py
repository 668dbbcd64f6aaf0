"""The experts' motion layer: a straight segment's IK never swings the arm across its
workspace in one control step."""

from __future__ import annotations

import numpy as np
import pytest

pytestmark = pytest.mark.sim


@pytest.mark.parametrize("rise", [0.2, 0.3, 0.5])
def test_a_pose_out_of_reach_holds_the_arm_where_it_is(rise: float) -> None:
    """An SO-101 asked for its hand 20-50 cm above where it is (beyond its reach): the
    closest answer the solver wanders to is 1.5-3 rad away from the arm's joints, which a
    joint command turns into a swing in one step that throws a held object. The driver
    counts the miss and holds instead."""
    from fsvla.env import make
    from fsvla.experts.motion import MAX_JOINT_STEP, ArmDriver, Pose
    from fsvla.experts.world import World
    from fsvla.resources import scenarios_dir

    env = make(str(scenarios_dir() / "force" / "push_block_gently_so101.fsv"), "L0", 0)
    env.reset()
    world = World.of_env(env)
    arm = world.arm_names[0]
    now, q0 = world.current_pose(arm), np.asarray(world.arm_joints(arm), dtype=np.float64)
    driver = ArmDriver(arm, world.kinematics(arm), now, q0, 1.0)
    q = driver.solve(Pose(now.p + np.array([0.0, 0.0, rise]), now.R))
    assert driver.ik_misses == 1
    assert float(np.max(np.abs(q - q0))) <= MAX_JOINT_STEP
    env.close()
