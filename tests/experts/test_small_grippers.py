"""One-jaw grippers (SO-101): the opening for a width comes from the jaw's geometry, and
the careful grip picks a block up without crushing it."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from fsvla.experts import rollout
from fsvla.experts.world import World

pytestmark = pytest.mark.sim

LIFT = """\
scenario lift_block_small_arm
  suite force
  task lift(object=block)
  embodiment so101
  instruction "Lift the red block."
  horizon 20 s

  object block: block(size=(3 cm, 3 cm, 4 cm), mass=80 g, color=red) at (8 cm, 3 cm)

  constrain grip: contact_force(gripper) <= 40 N warn 10 N

  success lifted(block, by=6 cm) for 1 s
"""


@pytest.fixture
def scenario(tmp_path: Path) -> Path:
    path = tmp_path / "lift.fsv"
    path.write_text(LIFT, encoding="utf-8")
    return path


def test_a_swinging_jaw_opens_as_far_as_its_geometry_says(scenario: Path) -> None:
    from fsvla.env import make

    env = make(str(scenario), "L0", 0)
    env.reset()
    world = World.of_env(env)
    arm = world.arm_names[0]
    assert not world.fingers_slide(arm)
    kin = world.kinematics(arm)
    for width in (0.01, 0.03, 0.05):
        fraction = world.opening_fraction(arm, width)
        a, b = kin.finger_points(fraction)[:2]
        assert np.linalg.norm(b - a) == pytest.approx(width, abs=5e-4)
    assert world.opening_fraction(arm, 2 * world.max_width(arm)) == 1.0
    assert world.opening_fraction(arm, 0.0) == 0.0
    env.close()


def test_careful_expert_lifts_a_block_with_the_so101_jaw(scenario: Path) -> None:
    result = rollout(str(scenario), "careful", "L0", 0)
    assert result.safe_success, result.summary()
    assert result.min_margin["grip"] > 0.0


POT = """\
scenario lift_pot_baxter
  suite force
  task bimanual_lift(object=pot)
  embodiment baxter
  instruction "Lift the pot with both hands."
  horizon 30 s

  object pot: pot(radius=8.1 cm, height=8.3 cm, mass=227 g) at (-12.5 cm, 2.4 cm)

  constrain grip: contact_force(gripper) <= 28 N warn 7 N

  success lifted(pot, by=10 cm) and upright(pot, within=15 deg) for 1 s
"""


def test_a_handle_wider_than_the_gripper_opens_is_taken_across_its_thickness(
        tmp_path: Path) -> None:
    """Baxter's fingers open 4.2 cm, a pot's handles are 5 cm wide: the hand closes across
    the handle's thickness, its fingers above and below it (across the width, both hands
    pressed the pot between them at 25-29 N, over the 28 N limit, and never held it)."""
    from fsvla.env import make
    from fsvla.experts.grasps import handle_grasp

    path = tmp_path / "pot.fsv"
    path.write_text(POT, encoding="utf-8")
    env = make(str(path), "L0", 0)
    env.reset()
    world = World.of_env(env)
    for arm in world.arm_names:
        grasp = handle_grasp(world, arm, "pot", "handle_left")
        closing = grasp.pose.R @ world.finger_axis(arm)
        assert abs(closing[2]) > 0.99 and grasp.width < world.max_width(arm)
    env.close()


@pytest.mark.slow
def test_baxter_lifts_a_pot_by_handles_wider_than_its_gripper(tmp_path: Path) -> None:
    path = tmp_path / "pot.fsv"
    path.write_text(POT, encoding="utf-8")
    result = rollout(str(path), "careful")
    assert result.safe_success, result.summary()


LOW_BLOCK_Z1 = """\
scenario lift_low_block_z1
  suite force
  task lift(object=block)
  embodiment z1
  instruction "Lift the purple block."
  horizon 10 s

  object block: block(size=(4.5 cm, 4.7 cm, 3.1 cm), mass=167 g, color=purple) at (6 cm, -10 cm) yaw 24 deg

  constrain grip: contact_force(gripper) <= 58 N warn 14 N

  success lifted(block, by=5 cm) for 0.5 s
"""


def test_the_z1s_fixed_jaw_stays_off_the_table_beside_a_low_block(tmp_path: Path) -> None:
    """The Z1's fixed jaw reaches 2 cm past its TCP: a grasp low on a 3 cm block put its
    tip on the table (280 N on the hand before the jaws closed)."""
    from fsvla.env import make
    from fsvla.experts.policy import make_expert

    path = tmp_path / "low_block.fsv"
    path.write_text(LOW_BLOCK_Z1, encoding="utf-8")
    env = make(str(path), "L0", 0)
    expert = make_expert(env, "careful")
    obs, _ = env.reset()
    expert.reset(None)
    world = World.of_env(env)
    arm = world.arm_names[0]
    assert world.hand_reach(arm) > 0.015  # the premise: the jaw reaches past the TCP
    step, labels, pressed = 0, set(), 0.0
    while "preclose" not in labels and step < 400:
        for action in expert.act(obs):
            label = expert.labels[step] if step < len(expert.labels) else ""
            obs, *_ = env.step(action)
            step += 1
            labels.add(label)
            if label in ("approach", "reach"):  # the jaws open beside the block: no touch
                pressed = max(pressed, world.hand_force(arm))
    env.close()
    assert {"approach", "reach", "preclose"} <= labels
    assert pressed < 0.5, f"the hand pressed with {pressed:.1f} N on its way down"
