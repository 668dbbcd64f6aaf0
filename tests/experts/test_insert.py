"""insert into an open container (a pot, a bowl): the careful hand lets the object go as
low as it stays clear of the container, never on its rim; on scenarios written for the
test, so that no shipped layout decides the outcome."""

from __future__ import annotations

import numpy as np
import pytest

from fsvla.experts.rollout import rollout

pytestmark = pytest.mark.sim

#: A Panda hand (21 cm across its fingers) over a 19 cm pot: coming down to the floor,
#: the hand lands on the rim.
KNIFE_IN_POT = """\
scenario knife_into_wide_pot
  suite force
  task insert(object=knife, target=pot)
  embodiment panda
  instruction "Put the knife into the pot."

  object knife: knife(length=16 cm) at (-13 cm, -19 cm) yaw -8 deg
  object pot: pot(radius=9.5 cm, height=9.6 cm, mass=120 g) at (23 cm, -8 cm)

  constrain grip: contact_force(gripper) <= 45 N warn 11 N

  success inside(knife, pot) and released(knife) for 0.5 s
"""

#: Baxter's fingers are long enough to set a block on the pot's floor, if the hand is
#: over the middle of the mouth and not on the rim (it shoved the pot away).
BLOCK_IN_POT_BAXTER = """\
scenario block_into_pot_baxter
  suite boundary
  task insert(object=block, target=pot)
  embodiment baxter
  instruction "Put the block into the pot."

  object block: block(size=(2.8 cm, 3.6 cm, 3.4 cm), mass=164 g) at (-17.7 cm, -11.7 cm)
  object pot: pot(radius=9.8 cm, height=8.4 cm, mass=186 g) at (8.9 cm, -14.4 cm)

  constrain separation(left_arm, right_arm) >= 1 cm warn 3 cm
  constrain contact_force(right_gripper) <= 60 N warn 15 N

  success inside(block, pot) and released(block) for 0.5 s
"""


def _write(tmp_path, name: str, text: str) -> str:
    path = tmp_path / f"{name}.fsv"
    path.write_text(text)
    return str(path)


def test_the_release_pose_keeps_the_hand_above_the_rim(tmp_path):
    """The lowest pose found for a Panda hand over a pot narrower than the hand: every
    piece of the hand outside the mouth stays above the rim, the object's centre is
    over the cavity."""
    from fsvla.env import make
    from fsvla.experts.tasks.cavity import HAND_CLEAR, hand_points, release_pose
    from fsvla.experts.world import World

    env = make(_write(tmp_path, "knife", KNIFE_IN_POT), "L0", 0)
    env.reset()
    world = World.of_env(env)
    arm = world.arm_names[0]
    drop, pose = release_pose(world, arm, "knife", "pot")[0]
    cavity = world.asset("pot").cavity
    root = world.body_pose("pot")
    axis = root.R @ np.asarray(cavity.pose.position) + root.p
    rim = float(world.bounds("pot")[1][2])
    points = hand_points(world, arm) @ pose.R.T + pose.p
    outside = np.linalg.norm(points[:, :2] - axis[:2], axis=1) > cavity.radius
    assert np.any(outside)  # the hand is wider than the mouth
    assert float(np.min(points[outside, 2])) >= rim + HAND_CLEAR - 1e-6
    tcp = world.current_pose(arm)
    lo, hi = world.bounds("knife")
    centre = pose.R @ tcp.R.T @ (0.5 * (lo + hi) - tcp.p) + pose.p
    assert np.linalg.norm(centre[:2] - axis[:2]) <= cavity.radius
    assert drop >= 0.0
    env.close()


@pytest.mark.slow
@pytest.mark.parametrize("name,text", [("knife", KNIFE_IN_POT), ("baxter", BLOCK_IN_POT_BAXTER)])
def test_careful_insert_into_a_pot_leaves_the_rim_alone(tmp_path, name, text):
    """Careful: the object ends in the pot and the hand never pushed on the rim (the plan
    that set the object on the floor pushed the Panda's hand onto the rim with 300 N, and
    Baxter's onto it until the pot was shoved away and the block fell outside the cavity)."""
    careful = rollout(_write(tmp_path, name, text), "careful", "L0", 0)
    assert careful.success and not careful.violation, careful.violated
