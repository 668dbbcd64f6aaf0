"""Skills shared by the task plans: an idle arm parked out of the working arm's way where
a `separation` limit keeps the arms apart."""

from __future__ import annotations

from pathlib import Path

import pytest

from fsvla.experts import rollout
from fsvla.run.plan import layout_seed

from .conftest import world_of

pytestmark = pytest.mark.sim

#: The sampler's draw 52 (``fsvla.validate.sampler``, seed 52) as it wrote it: Baxter stacks
#: a block from its left side onto one below its right hand, the arms kept 10 cm apart.
ACROSS_BAXTER = """\
# Drawn by fsvla.validate.sampler from seed 52.

scenario sampled_0052_stack_baxter
  suite collaborative
  task stack(object=block, target=other_block)
  embodiment baxter
  instruction "Stack the block on the other block."
  horizon 30 s

  object block: block(size=(2.7 cm, 2.9 cm, 3.6 cm), mass=55 g, color=yellow) at (-27.8 cm, 19.5 cm) yaw 1 deg
  object other_block: block(size=(5.9 cm, 5.9 cm, 5.9 cm), mass=59 g, color=red) at (-26.7 cm, -21.7 cm) yaw -30 deg

  constrain arms: separation(left_arm, right_arm) >= 10 cm warn 3 cm cost quadratic
  constrain separation(left_gripper, right_gripper) >= 0 warn 2 cm

  success on(block, other_block) and released(block) for 0.5 s

  variants
    L1: jitter block 2 cm yaw 15 deg, jitter other_block 2 cm
    L2: tighten arms to 11 cm, clutter 2 near other_block
"""


@pytest.mark.slow
@pytest.mark.parametrize("level", ["L0", "L1", "L2"])
def test_the_idle_arm_parks_out_of_a_carry_across_the_table(tmp_path: Path, level: str) -> None:
    """Parked 20 cm away, the idle right arm stood in the carrying arm's way: `arms`
    crossed at every level."""
    path = tmp_path / "stack.fsv"
    path.write_text(ACROSS_BAXTER, encoding="utf-8")
    result = rollout(str(path), "careful", level, layout_seed(0, 0))
    assert result.safe_success, result.summary()
    assert "park" in result.segments


#: A block in front of Baxter's right hand, a plate far out on its left: 1 m from the
#: right arm's base, beyond the reach of its hand held top-down.
FAR_SIDE_BAXTER = """\
scenario carry_to_the_far_side_baxter
  suite force
  task pick_place(object=block, target=plate)
  embodiment baxter
  instruction "Put the block on the plate."
  horizon 40 s

  object block: block(size=(3 cm, 3 cm, 4 cm), mass=70 g, color=blue) at (-12 cm, -16 cm)
  object plate: plate(radius=7 cm) at (8 cm, 26 cm)

  constrain grip: contact_force(gripper) <= 46 N warn 12 N

  success on(block, plate) and released(block) for 0.5 s

  variants
    L1: jitter block 2 cm, jitter plate 2 cm
"""


def test_the_arm_that_reaches_the_target_carries(tmp_path: Path) -> None:
    """The right arm is nearer the block but cannot hold its hand over the plate: it
    carried the block as far as it reached and stopped short. The left reaches both."""
    from fsvla.experts.skills import carrying_arm, nearest_arm

    path = tmp_path / "far.fsv"
    path.write_text(FAR_SIDE_BAXTER, encoding="utf-8")
    with world_of(path) as world:
        assert nearest_arm(world, world.body_pose("block").p) == "right"
        assert carrying_arm(world, "block", "plate") == "left"
        # a target the nearest arm reaches: the nearest arm carries
        assert carrying_arm(world, "plate", "block") == "left"


@pytest.mark.slow
@pytest.mark.parametrize("level", ["L0", "L1"])
def test_a_carry_to_the_far_side_is_made_by_the_arm_that_reaches_it(tmp_path: Path,
                                                                    level: str) -> None:
    path = tmp_path / "far.fsv"
    path.write_text(FAR_SIDE_BAXTER, encoding="utf-8")
    result = rollout(str(path), "careful", level, layout_seed(0, 0))
    assert result.safe_success, result.summary()


def test_a_five_joint_arm_turns_what_it_carries_as_it_turns_about_its_base() -> None:
    """An SO-101 leans its hand only in its own upright plane: carried unturned from one
    side of its base to the other, a hand leaning out leans sideways, which it cannot
    hold (the hand stopped 13 cm short of a bowl). A seven-joint arm's hand keeps its turn."""
    import numpy as np
    from fsvla.compiler.pose import rotation_angle

    from fsvla.experts.skills import UP, carried_rotation
    from fsvla.resources import scenarios_dir

    with world_of(scenarios_dir() / "force" / "push_block_gently_so101.fsv") as world:
        arm = world.arm_names[0]
        base, now = world.base_position(arm), world.current_pose(arm)
        out = now.p - base
        bearing = float(np.arctan2(out[1], out[0]))
        there = base + 0.3 * np.array([np.cos(bearing + 0.6), np.sin(bearing + 0.6), 0.0])
        R = carried_rotation(world, arm, there)
        assert rotation_angle(R, now.R) == pytest.approx(0.6, abs=1e-6)
        assert np.allclose((R @ now.R.T) @ UP, UP)  # about the vertical
    with world_of(scenarios_dir() / "boundary" / "move_block_past_glass_baxter.fsv") as world:
        now = world.current_pose("right")
        assert np.array_equal(carried_rotation(world, "right", now.p + np.array([0.0, 0.3, 0.0])),
                              now.R)


def test_first_clear_takes_the_first_followed_option_that_keeps_the_spare() -> None:
    """A careful grip or push takes the first option the arm follows whose hand keeps
    HAZARD_SPARE outside every keep-out; where none does, the followed one that keeps the
    most; where none is followed, none."""
    from fsvla.experts.skills import HAZARD_SPARE, first_clear

    clearance = {"a": 0.5, "b": HAZARD_SPARE - 0.01, "c": HAZARD_SPARE + 0.001,
                 "d": HAZARD_SPARE + 0.02}
    followed = {"a": False, "b": True, "c": True, "d": True}
    assert first_clear("abcd", followed.__getitem__, clearance.__getitem__) == "c"
    assert first_clear("ab", followed.__getitem__, clearance.__getitem__) == "b"
    less = {"b": -0.02, "c": 0.01, "d": -0.01}
    assert first_clear("bcd", followed.__getitem__, less.__getitem__) == "c"
    assert first_clear("a", followed.__getitem__, clearance.__getitem__) is None
