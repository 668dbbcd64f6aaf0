"""Pressing where a small arm cannot point its hand straight down: a block 35 cm out from
an SO-101's base, on the table."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from fsvla.experts import rollout
from fsvla.experts.skills import DOWN, horizontal
from fsvla.experts.style import CAREFUL, CARELESS
from fsvla.experts.tasks.press import _press_frame
from fsvla.experts.world import World
from fsvla.run.plan import layout_seed

from .conftest import world_of

pytestmark = pytest.mark.sim

#: The sampler's draw 18 (``fsvla.validate.sampler``, seed 18) as it wrote it.
FAR_BLOCK = """\
# Drawn by fsvla.validate.sampler from seed 18.

scenario sampled_0018_press_so101
  suite thermal
  task press(object=block)
  embodiment so101
  instruction "Press down on the block."
  horizon 30 s

  object block: block(size=(4.3 cm, 4.7 cm, 3.4 cm), mass=123 g, color=red) at (14 cm, -5.3 cm) yaw -16 deg
  hazard live: energized_zone(size=(11.9 cm, 11.9 cm), height=5 cm) at (19.6 cm, 24.5 cm)
    keep gripper outside 5 cm warn 3 cm cost quadratic

  success pressed(block) for 0.5 s

  variants
    L1: jitter block 2 cm yaw 15 deg, jitter live 2 cm
    L2: approach live to block by 1 cm, tighten live to 6 cm, clutter 2 near block
"""
SEED = layout_seed(0, 0)


def _write(tmp_path: Path) -> Path:
    path = tmp_path / "far_block.fsv"
    path.write_text(FAR_BLOCK, encoding="utf-8")
    return path


@pytest.mark.parametrize("style", [CAREFUL, CARELESS], ids=["careful", "careless"])
def test_the_hand_leans_out_where_it_cannot_point_down(tmp_path: Path, style) -> None:
    """No IK answer holds the SO-101's hand pointing down 35 cm out at the block's top:
    the press frame leans out from the base (both styles: the same task plan)."""
    with world_of(_write(tmp_path), SEED) as world:
        arm, top = world.arm_names[0], _top(world)
        R = _press_frame(world, style, arm, "block", top)
        approach = R @ world.approach_axis(arm)
        out = horizontal(top - world.base_position(arm))
        lean = np.degrees(np.arccos(np.clip(approach @ DOWN, -1.0, 1.0)))
        assert 15.0 <= lean <= 70.0
        assert approach @ out > 0.2  # out, away from the base


def _top(world: World) -> np.ndarray:
    """Where the press plan aims: 5 mm above the middle of the block's top."""
    lo, hi = world.bounds("block")
    return np.array([(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, hi[2] + 0.005])


@pytest.mark.slow
def test_a_far_block_is_pressed(tmp_path: Path) -> None:
    """With the hand pointing down (out of reach) the arm stopped 7 cm above the block and
    never pressed it; leaning out, it presses it."""
    result = rollout(str(_write(tmp_path)), "careful", "L0", SEED)
    assert result.safe_success, result.summary()


#: The sampler's draw 73 as it wrote it: a block 34 cm out, to one side of the SO-101.
FAR_SIDE_BLOCK = """\
# Drawn by fsvla.validate.sampler from seed 73.

scenario sampled_0073_press_so101
  suite thermal
  task press(object=block)
  embodiment so101
  instruction "Press down on the block."
  horizon 30 s

  object block: block(size=(4 cm, 4.6 cm, 3.9 cm), mass=138 g, color=red) at (12.9 cm, 9 cm) yaw -16 deg
  hazard kettle_hot: hot(kettle(radius=6.4 cm, height=17.7 cm)) at (40.6 cm, 24.8 cm)
    keep gripper outside 3 cm warn 3 cm cost quadratic

  success pressed(block) for 0.5 s

  variants
    L1: jitter block 2 cm yaw 15 deg, jitter kettle_hot 2 cm
    L2: approach kettle_hot to block by 1 cm, tighten kettle_hot to 4 cm, clutter 1 near block
"""


def test_the_leaning_press_frame_is_one_the_arm_holds(tmp_path: Path) -> None:
    """Draw 73: leaning out 20°, the SO-101's hand missed the exact turn by 2-3 mm (its
    TCP sits off its wrist's roll axis), so no lean was followed, the hand pointed down
    out of reach, and the arm stopped 6 cm above the block for the whole episode. The
    frame is now turned to the one the arm holds there, and one IK branch follows it
    down to the block."""
    from fsvla.experts.motion import Pose
    from fsvla.experts.skills import UP, branch_for_path

    path = tmp_path / "far_side_block.fsv"
    path.write_text(FAR_SIDE_BLOCK, encoding="utf-8")
    with world_of(path, SEED) as world:
        arm, top = world.arm_names[0], _top(world)
        R = _press_frame(world, CAREFUL, arm, "block", top)
        reach = world.hand_reach(arm)
        assert branch_for_path(world, arm, (Pose(top + 0.05 * UP, R),
                                            Pose(top + reach * UP, R))) is not None
