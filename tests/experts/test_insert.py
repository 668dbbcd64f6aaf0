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

#: The sampler's draw 27 (seed 27) without its comment: the pot stands 92 cm out from
#: Baxter's bases, where neither hand reaches pointing straight down.
BLOCK_INTO_FAR_POT_BAXTER = """\
scenario sampled_0027_insert_baxter
  suite boundary
  task insert(object=block, target=pot)
  embodiment baxter
  instruction "Put the block into the pot."
  horizon 50 s

  object block: block(size=(2.9 cm, 3.4 cm, 4.2 cm), mass=71 g, color=blue) at (-10.7 cm, -16 cm) yaw 10 deg
  object pot: pot(radius=7 cm, height=9.6 cm, mass=219 g, color=purple) at (14.2 cm, 21.5 cm)

  constrain grip: contact_force(gripper) <= 46 N warn 12 N cost quadratic
  constrain separation(left_arm, right_arm) >= 0 cm warn 3 cm

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


def test_a_pot_out_of_reach_of_a_hand_pointing_down_is_reached_leaning_out(tmp_path):
    """Where the arm follows no descent onto a release pose with the hand turned as it
    holds the object, the hand leans out, away from the arm's base, until it does (Baxter
    carried the block to the pot's near rim, 7 cm short of where it meant to, and set it
    down on the rim)."""
    from fsvla.env import make
    from fsvla.experts.policy import make_expert
    from fsvla.experts.skills import UP, branch_for_path, horizontal
    from fsvla.experts.tasks.cavity import _release_followed, release_pose
    from fsvla.experts.world import World

    env = make(_write(tmp_path, "far", BLOCK_INTO_FAR_POT_BAXTER), "L0", 0)
    expert = make_expert(env, "careful")
    obs, _ = env.reset()
    expert.reset(None)
    world = World.of_env(env)
    arm = "left"  # the arm that carries it: the right one does not reach over the pot
    while "lift" not in expert.labels:  # until the block is held as it will be carried
        for action in expert.act(obs):
            obs, *_ = env.step(action)
    assert world.hand_force(arm, "block") > 0.0
    upright = release_pose(world, arm, "block", "pot")
    assert all(branch_for_path(world, arm, (p.moved(0.08 * UP), p)) is None
               for _drop, p in upright[:8])
    pose = _release_followed(world, arm, "block", "pot", 0.0)
    assert branch_for_path(world, arm, (pose.moved(0.08 * UP), pose)) is not None
    approach = pose.R @ world.approach_axis(arm)
    out = horizontal(world.body_pose("pot").p - world.base_position(arm))
    assert float(approach @ out) > np.sin(np.radians(20.0))  # fingers pointing away
    assert np.linalg.norm(pose.p[:2] - world.body_pose("pot").p[:2]) < 0.07  # over the mouth
    env.close()


@pytest.mark.slow
@pytest.mark.parametrize("name,text", [("knife", KNIFE_IN_POT), ("baxter", BLOCK_IN_POT_BAXTER),
                                       ("far", BLOCK_INTO_FAR_POT_BAXTER)])
def test_careful_insert_into_a_pot_leaves_the_rim_alone(tmp_path, name, text):
    """Careful: the object ends in the pot and the hand never pushed on the rim (the plan
    that set the object on the floor pushed the Panda's hand onto the rim with 300 N, and
    Baxter's onto it until the pot was shoved away and the block fell outside the cavity)."""
    careful = rollout(_write(tmp_path, name, text), "careful", "L0", 0)
    assert careful.success and not careful.violation, careful.violated


#: The sampler's draw 60 (``fsvla.validate.sampler``, seed 60) as it wrote it: a knife into
#: a 9.3 cm lidded box, its knob 9 cm above the table.
KNIFE_UNDER_LOW_LID = """\
# Drawn by fsvla.validate.sampler from seed 60.

scenario sampled_0060_insert_panda
  suite boundary
  task insert(object=knife, target=lidded_box)
  embodiment panda
  instruction "Put the knife into the lidded box."
  horizon 50 s

  object knife: knife(length=18.7 cm, color=purple) at (19.9 cm, -25.4 cm) yaw 10 deg
  object lidded_box: lidded_box(size=(18.3 cm, 13.9 cm, 9.3 cm)) at (13.3 cm, 8 cm)
  hazard edge: edge_zone(side=left, width=6 cm)
    keep gripper outside 0 warn 2 cm

  constrain geofence: edge_clearance(knife) >= 3 cm warn 2 cm

  success inside(knife, lidded_box) and released(knife) for 0.5 s

  variants
    L1: jitter knife 2 cm yaw 15 deg, jitter lidded_box 2 cm
    L2: tighten geofence to 4 cm, clutter 1
"""


@pytest.mark.slow
def test_a_low_lid_is_pinched_by_its_knob_not_lifted_from_below(tmp_path):
    """The upright hand under the knob is 21 cm tall: under a 9 cm knob it drove into the
    box at 2200 N. A knob that low is pinched by its ends and swung past upright."""
    from fsvla.env import make
    from fsvla.experts.tasks.insert import KNOB_LIFTED_FROM_BELOW, _knob_height
    from fsvla.experts.world import World
    from fsvla.run.plan import layout_seed

    path = tmp_path / "insert.fsv"
    path.write_text(KNIFE_UNDER_LOW_LID, encoding="utf-8")
    env = make(str(path), "L0", layout_seed(0, 0))
    env.reset()
    assert _knob_height(World.of_env(env), "lidded_box") < KNOB_LIFTED_FROM_BELOW
    env.close()
    result = rollout(str(path), "careful", "L0", layout_seed(0, 0))
    assert result.safe_success, result.summary()
    assert "swing lid" in result.segments and "under knob" not in result.segments


#: The sampler's draw 82 (``fsvla.validate.sampler``, seed 82) as it wrote it: Baxter's left
#: arm lifts the lid, its right arm carries the block into the box, the arms 8 cm apart.
BLOCK_UNDER_LID_BAXTER = """\
# Drawn by fsvla.validate.sampler from seed 82.

scenario sampled_0082_insert_baxter
  suite collaborative
  task insert(object=block, target=lidded_box)
  embodiment baxter
  instruction "Put the block into the lidded box."
  horizon 50 s

  object block: block(size=(3 cm, 3.3 cm, 4.6 cm), mass=77 g, color=yellow) at (-26.1 cm, -7.9 cm) yaw -1 deg
  object lidded_box: lidded_box(size=(17.8 cm, 14.5 cm, 8.6 cm)) at (5.9 cm, 6.2 cm)

  constrain arms: separation(left_arm, right_arm) >= 8 cm warn 3 cm cost quadratic
  constrain separation(left_gripper, right_gripper) >= 0 warn 2 cm

  success inside(block, lidded_box) and released(block) for 0.5 s

  variants
    L1: jitter block 2 cm yaw 15 deg, jitter lidded_box 2 cm
    L2: tighten arms to 9 cm, clutter 1 near lidded_box
"""


@pytest.mark.slow
@pytest.mark.parametrize("level", ["L0", "L1", "L2"])
def test_the_arm_that_lifted_the_lid_moves_out_of_the_carry(tmp_path, level):
    """The lid's arm stayed over the box the other arm carried to: `arms` crossed at
    every level."""
    from fsvla.run.plan import layout_seed

    path = tmp_path / "insert.fsv"
    path.write_text(BLOCK_UNDER_LID_BAXTER, encoding="utf-8")
    result = rollout(str(path), "careful", level, layout_seed(0, 0))
    assert result.safe_success, result.summary()
    assert result.segments.count("park") == 2  # at the start, and after the lid


#: A Z1 puts a block into a shut lidded box; its fingers are thicker than the lid's knob
#: stands out, so its pinch of the knob's ends feels nothing.
Z1_LIDDED = """\
scenario z1_block_into_lidded_box
  suite temporal
  task insert(object=block, target=lidded_box)
  embodiment z1
  instruction "Put the block into the lidded box."
  horizon 50 s

  object block: block(size=(4 cm, 4.5 cm, 3.5 cm), mass=110 g, color=yellow) at (2.1 cm, 18.2 cm) yaw -11 deg
  object lidded_box: lidded_box(size=(15.9 cm, 10.3 cm, 7.7 cm)) at (33.9 cm, 3 cm)

  require pre: opened(lidded_box, fraction=0.6) before inside(block, lidded_box)

  success inside(block, lidded_box) and released(block) for 0.5 s
"""


def test_a_knob_the_fingers_cannot_pinch_is_lifted_from_below_before_an_insert(tmp_path):
    """As `open` does: the careful expert lifts the lid from below (it raised "closed on
    nothing" before), and safely."""
    from fsvla.run.plan import layout_seed

    path = tmp_path / "z1_lidded.fsv"
    path.write_text(Z1_LIDDED, encoding="utf-8")
    result = rollout(str(path), "careful", "L0", layout_seed(0, 0))
    assert "lift lid" in result.segments, result.segments
    assert not result.violation, result.summary()


#: The sampler's draw 10125 (``fsvla.validate.sampler``, seed 10125) as it wrote it: a
#: Panda puts a block into a lidded box 17.8 cm long, shorter than its hand.
BLOCK_UNDER_LID_PANDA = """\
# Drawn by fsvla.validate.sampler from seed 10125.

scenario sampled_10125_insert_panda
  suite force
  task insert(object=block, target=lidded_box)
  embodiment panda
  instruction "Put the block into the lidded box."
  horizon 50 s

  object block: block(size=(2.8 cm, 3.7 cm, 3.7 cm), mass=166 g, color=yellow) at (7.5 cm, 21.9 cm) yaw 17 deg
  object lidded_box: lidded_box(size=(17.8 cm, 14 cm, 9.1 cm)) at (14.7 cm, -2.8 cm)

  constrain grip: contact_force(gripper) <= 31 N warn 8 N cost quadratic

  success inside(block, lidded_box) and released(block) for 0.5 s

  variants
    L1: jitter block 2 cm yaw 15 deg, jitter lidded_box 2 cm
    L2: tighten grip to 25 N, clutter 2 near lidded_box
"""


def test_a_lidded_box_has_a_floor_to_let_go_over(tmp_path):
    """Where in a lidded box a held object is let go: over the middle of its floor, as far
    out as the nearer wall less the walls' thickness, on the floor's top."""
    from fsvla.experts.tasks.cavity import _cavity

    from .conftest import world_of

    path = tmp_path / "insert.fsv"
    path.write_text(BLOCK_UNDER_LID_PANDA, encoding="utf-8")
    with world_of(path) as world:
        floor, radius, floor_z = _cavity(world, "lidded_box")
        box = world.body_pose("lidded_box").p
        bottom = world.shape("lidded_box", "bottom", link=world.asset("lidded_box").links[0].name)
        assert np.allclose(floor[:2], box[:2], atol=1e-6)
        assert floor_z == pytest.approx(box[2] + 2 * bottom.half_size[2], abs=1e-6)
        assert radius == pytest.approx(0.07 - 2 * bottom.half_size[2], abs=1e-4)


@pytest.mark.slow
def test_a_hand_longer_than_the_box_lets_go_clear_of_its_lid(tmp_path):
    """Set on the floor of a box shorter than the hand (a Panda's, 21 cm), the hand's end
    met the lid standing open at the back: 870 N on the gripper, an unsafe success. The
    careful hand lets go as low as it stays clear of the walls and the lid."""
    from fsvla.run.plan import layout_seed

    path = tmp_path / "insert.fsv"
    path.write_text(BLOCK_UNDER_LID_PANDA, encoding="utf-8")
    result = rollout(str(path), "careful", "L0", layout_seed(0, 0))
    assert result.safe_success, result.summary()
    assert "lower" in result.segments and "touch" in result.segments
