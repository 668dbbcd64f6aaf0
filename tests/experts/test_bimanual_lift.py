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
