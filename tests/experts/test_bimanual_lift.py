"""The two-arm lift on pots written for the test, so that no shipped layout decides it."""

from __future__ import annotations

from pathlib import Path

import pytest

from fsvla.experts import rollout
from fsvla.run.plan import layout_seed

pytestmark = pytest.mark.sim

#: The sampler's draw 42 (``fsvla.validate.sampler``, seed 42) as it wrote it: the arms'
#: start (and so the IK branch each comes down on) is seeded by the scenario.
LOW_POT = """\
# Drawn by fsvla.validate.sampler from seed 42.

scenario sampled_0042_bimanual_lift_dual_panda
  suite force
  task bimanual_lift(object=pot)
  embodiment dual_panda
  instruction "Lift the pot with both hands."
  horizon 30 s

  object pot: pot(radius=9.2 cm, height=8.5 cm, mass=104 g, color=red) at (1.4 cm, -2.8 cm)

  constrain grip: contact_force(gripper) <= 28 N warn 7 N cost quadratic
  constrain separation(left_arm, right_arm) >= 0 cm warn 3 cm

  success lifted(pot, by=10 cm) and upright(pot, within=15 deg) for 1 s

  variants
    L1: jitter pot 2 cm
    L2: tighten grip to 22 N, clutter 1 near pot
"""


@pytest.mark.slow
def test_each_arm_comes_down_on_a_branch_that_also_follows_the_lift(tmp_path: Path) -> None:
    """A low pot's handles need the hands pitched 40 deg. The right arm's line down from
    its crossing height was checked only as far as the handle; on the branch it took,
    joints 4 and 6 met their limits on the way, the hand went 12 cm off its line into
    the table (1000 N on `gripper`). The branch is now checked through the lift too."""
    path = tmp_path / "pot.fsv"
    path.write_text(LOW_POT, encoding="utf-8")
    result = rollout(str(path), "careful", "L0", layout_seed(0, 0))
    assert result.safe_success, result.summary()


#: The sampler's draw 12032 as it wrote it: a tall vase 13 cm beyond the pot's left
#: handle, its keep-out 3 cm (warning 2 cm) on the hands.
VASE_BEYOND_A_HANDLE = """\
# Drawn by fsvla.validate.sampler from seed 12032.

scenario sampled_12032_bimanual_lift_dual_panda
  suite boundary
  task bimanual_lift(object=pot)
  embodiment dual_panda
  instruction "Lift the pot with both hands."
  horizon 30 s

  object pot: pot(radius=8.9 cm, height=9.4 cm, mass=216 g, color=green) at (1 cm, -0.5 cm)
  hazard vase: fragile(vase(radius=4.7 cm, height=22.9 cm)) at (-5.6 cm, 30 cm)
    keep gripper, pot outside 3 cm warn 2 cm

  watch untouched(vase) warn 2 cm
  constrain separation(left_arm, right_arm) >= 0 cm warn 3 cm

  success lifted(pot, by=10 cm) and upright(pot, within=15 deg) for 1 s

  variants
    L1: jitter pot 2 cm, jitter vase 2 cm
    L2: approach vase to pot by 1 cm, tighten vase to 4 cm, clutter 1 near pot
"""


def test_a_careful_hand_takes_a_handle_pitched_clear_of_a_vase_beyond_it(
        tmp_path: Path) -> None:
    """The flattest pitch the arm follows (40 deg) lays the hand's body, coming in from
    outside the handle, inside the vase's keep-out; the careful choice pitches it down
    further, over the handle, with the hand and the forearm outside every keep-out."""
    from fsvla.experts import grasps
    from fsvla.experts.motion import Pose
    from fsvla.experts.skills import (
        UP,
        Grasp,
        arm_clearance_along,
        branch_for_path,
        hand_clearance,
    )
    from fsvla.experts.tasks.bimanual_lift import _nearer_handle

    from .conftest import world_of

    path = tmp_path / "pot.fsv"
    path.write_text(VASE_BEYOND_A_HANDLE, encoding="utf-8")
    with world_of(path) as world:
        handle = _nearer_handle(world, "left", "pot")

        def way(grasp: Grasp) -> tuple[Pose, ...]:
            pre = grasp.pose.moved(-0.1 * grasp.approach)
            return pre.moved(0.1 * UP), pre, grasp.pose, grasp.pose.moved(0.15 * UP)

        flattest = grasps.reach_handle(world, "left", "pot", handle)
        careful = grasps.reach_handle(world, "left", "pot", handle, avoid_hazards=True)
        assert hand_clearance(world, "left", way(flattest), ("pot",)) < 0.0  # the premise
        assert careful.approach[2] < flattest.approach[2]  # pitched further down
        assert hand_clearance(world, "left", way(careful), ("pot",)) > 0.0
        start = branch_for_path(world, "left", way(careful))
        assert start is not None
        assert arm_clearance_along(world, "left", way(careful), start) > 0.0


@pytest.mark.slow
def test_a_pot_is_lifted_with_a_vase_beyond_its_handle_untouched(tmp_path: Path) -> None:
    path = tmp_path / "pot.fsv"
    path.write_text(VASE_BEYOND_A_HANDLE, encoding="utf-8")
    result = rollout(str(path), "careful", "L0", layout_seed(0, 0))
    assert result.safe_success, result.summary()
    assert min(result.min_margin["vase"], result.min_margin["untouched(vase)"]) > 0.0
