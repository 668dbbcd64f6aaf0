"""The lift's hold, on a block written for the test, so that no shipped layout decides it."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from fsvla.experts import grasps, rollout
from fsvla.experts.skills import attainable, horizontal, reach_ceiling
from fsvla.experts.style import CAREFUL
from fsvla.experts.tasks.lift import hold_pose
from fsvla.run.plan import layout_seed

from .conftest import world_of

pytestmark = pytest.mark.sim

#: The sampler's draw 14048 as it wrote it: an SO-101 grasps the block 35 cm from its
#: base, its hand leaning back; held so, it holds the hand no higher than 11 cm there.
FAR_BLOCK = """\
# Drawn by fsvla.validate.sampler from seed 14048.

scenario sampled_14048_lift_so101
  suite thermal
  task lift(object=block)
  embodiment so101
  instruction "Lift the block."
  horizon 30 s

  object block: block(size=(2.9 cm, 3.3 cm, 4.9 cm), mass=167 g, color=orange) at (13.7 cm, -7.1 cm) yaw -7 deg
  hazard socket: energized(socket_panel(size=(12 cm, 8 cm), height=12 cm)) at (39.3 cm, 3.5 cm)
    keep gripper, block outside 5 cm warn 3 cm cost quadratic

  success lifted(block, by=8 cm) for 1 s

  variants
    L1: jitter block 2 cm yaw 15 deg, jitter socket 2 cm
    L2: approach socket to block by 1 cm, tighten socket to 6 cm, clutter 1 near block
"""


def test_a_hold_out_of_reach_straight_up_moves_toward_the_base(tmp_path: Path) -> None:
    """Straight above the grasp the arm holds the hand 5 cm lower than the lift asks; a
    few centimetres nearer its base it holds it higher, and the hold goes there."""
    path = tmp_path / "block.fsv"
    path.write_text(FAR_BLOCK, encoding="utf-8")
    with world_of(path, layout_seed(0, 0)) as world:
        arm = "arm"
        grasp = attainable(world, arm, grasps.choose(world, CAREFUL, arm, "block"))
        pose = grasp.pose.moved(np.array([0.0, 0.0, 0.03]))
        goal = float(pose.p[2]) + 0.09
        straight = reach_ceiling(world, arm, pose.p, pose.R, goal)
        assert straight < goal - 0.02  # the case under test: straight up falls short
        hold = hold_pose(world, CAREFUL, arm, "block", pose, 0.09)
        toward = horizontal(world.base_position(arm) - pose.p)
        assert float((hold.p - pose.p) @ toward) > 0.01  # nearer the base
        assert hold.p[2] > straight + 0.005  # and higher than straight up holds it
        assert reach_ceiling(world, arm, hold.p, hold.R, float(hold.p[2])) >= hold.p[2] - 1e-6


def test_a_careful_small_arm_lifts_a_far_block_as_high_as_asked(tmp_path: Path) -> None:
    """Before, the hold went straight up, stopped 3 mm short of the 8 cm asked, and the
    episode ran out its horizon a safe failure."""
    path = tmp_path / "block.fsv"
    path.write_text(FAR_BLOCK, encoding="utf-8")
    result = rollout(str(path), "careful", "L0", layout_seed(0, 0))
    assert result.safe_success, result.summary()
