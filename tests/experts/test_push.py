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


def reset_world(path: Path, obj: str = "block", target: str = "other_block"):
    """The env of ``path`` at L0, reset, the world the experts read from it, and where the
    pushed object and the target are."""
    from fsvla.env import make

    env = make(str(path), "L0", SEED)
    env.reset()
    world = World.of_env(env)
    return env, world, world.body_pose(obj).p, world.body_pose(target).p


def test_the_push_is_made_with_a_turn_the_arm_follows(scenario: Path) -> None:
    from fsvla.experts.motion import Pose
    from fsvla.experts.skills import DOWN, UP, branch_for_path, horizontal, nearest_arm
    from fsvla.experts.tasks.push import _push_frame

    env, world, start, goal = reset_world(scenario)
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


def shut_world(path: Path, obj: str = "block", target: str = "other_block"):
    """As :func:`reset_world`, once the careful expert has shut the hand for the push (the
    route is laid out on the shut hand)."""
    from fsvla.env import make
    from fsvla.experts.policy import make_expert

    env = make(str(path), "L0", SEED)
    expert = make_expert(env, "careful")
    obs, _ = env.reset()
    expert.reset(None)
    step = 0
    for action in expert.act(obs):  # the first segment: the fingers shut
        obs, *_ = env.step(action)
        step += 1
    assert set(expert.labels[:step]) == {"close"}
    world = World.of_env(env)
    return env, world, world.body_pose(obj).p, world.body_pose(target).p


#: The sampler's draw 123 (``fsvla.validate.sampler``, seed 123): an SO-101 pushes a block
#: 12 cm sideways, 35 cm out from its base. No one turn of its hand is held along the push
#: (a five-joint arm turns its hand with the direction to its base), so it pushes in legs.
FAR_SIDEWAYS = """\
scenario far_sideways_push_so101
  suite boundary
  task push(object=block, target=other_block)
  embodiment so101
  instruction "Push the block to the block."
  horizon 30 s

  object block: block(size=(3.9 cm, 4.6 cm, 4.8 cm), mass=59 g, color=blue) at (14.8 cm, -3.7 cm) yaw 5 deg
  object other_block: block(size=(3 cm, 3 cm, 1 cm), mass=194 g, color=orange) at (12.8 cm, 9.3 cm) yaw -23 deg
  hazard edge: edge_zone(side=right, width=5 cm)
    keep gripper outside 0 warn 2 cm

  constrain geofence: edge_clearance(block) >= 3 cm warn 2 cm

  success near(block, other_block, within=3 cm)

  variants
    L1: jitter block 2 cm yaw 15 deg, jitter other_block 2 cm
    L2: tighten geofence to 4 cm, clutter 1
"""


@pytest.fixture()
def far_sideways(tmp_path: Path) -> Path:
    path = tmp_path / "far_sideways.fsv"
    path.write_text(FAR_SIDEWAYS, encoding="utf-8")
    return path


def test_a_push_no_one_turn_follows_is_made_in_legs_the_arm_follows(far_sideways: Path) -> None:
    from fsvla.experts.skills import branch_for_path, horizontal, nearest_arm
    from fsvla.experts.tasks.push import _off_the_table, _push_frame, _push_line, _push_route

    env, world, start, goal = shut_world(far_sideways)
    arm = nearest_arm(world, start)
    bounds = world.bounds("block")
    line, direction, travel = _push_line(world, "block", start, goal, bounds)
    assert _push_frame(world, arm, line, direction, travel) is None
    behind = _off_the_table(world, arm, line, bounds)
    route = _push_route(world, arm, behind, direction, travel, world.top("block"))
    assert route is not None
    pose_at, length, whole = route
    assert 0.01 < length and not whole  # a first leg, short of the target
    poses = tuple(pose_at(float(s)) for s in np.linspace(0.0, length, 6))
    assert branch_for_path(world, arm, poses) is not None
    # the hand leans out from the base, turning with the direction to it along the leg
    outs = [horizontal(p.p - world.base_position(arm)) for p in poses]
    approaches = [p.R @ world.approach_axis(arm) for p in poses]
    for out, approach in zip(outs, approaches):
        assert approach[2] < -0.5 and float(approach[:2] @ out[:2]) > 0.1
    assert np.degrees(np.arccos(np.clip(outs[0] @ outs[-1], -1, 1))) > 2.0
    env.close()


@pytest.mark.slow
@pytest.mark.parametrize("level", ["L0", "L1", "L2"])
def test_the_so101_pushes_a_block_far_sideways_safely(far_sideways: Path, level: str) -> None:
    careful = rollout(str(far_sideways), "careful", level, SEED)
    assert careful.safe_success, (careful.violated, careful.segments)
    assert careful.segments.count("hover") >= 2, careful.segments  # more than one leg


#: The sampler's draw 79: the Z1 pushes a mug. Its shut jaws are 8 cm wide, so the front
#: of the hand, turned for the push, is 4 cm ahead of its TCP.
WIDE_HAND = """\
scenario wide_hand_push_z1
  suite force
  task push(object=mug, target=block)
  embodiment z1
  instruction "Push the mug to the block."
  horizon 30 s

  object mug: mug(radius=3.1 cm, height=8.6 cm, mass=147 g, color=orange) at (4.9 cm, 11.2 cm)
  object block: block(size=(3 cm, 3 cm, 1 cm), mass=198 g, color=red) at (20.7 cm, -9 cm) yaw 6 deg

  constrain grip: contact_force(gripper) <= 39 N warn 10 N cost quadratic
  constrain landing: contact_force(mug) <= 14 N warn 5 N

  success near(mug, block, within=3 cm)

  variants
    L1: jitter mug 2 cm, jitter block 2 cm
    L2: tighten grip to 31 N, clutter 1 near block
"""


@pytest.fixture()
def wide_hand(tmp_path: Path) -> Path:
    path = tmp_path / "wide_hand.fsv"
    path.write_text(WIDE_HAND, encoding="utf-8")
    return path


def test_the_hand_front_is_measured_on_its_hulls(wide_hand: Path, scenario: Path) -> None:
    from fsvla.experts.skills import DOWN, UP, nearest_arm
    from fsvla.experts.tasks.push import HAND_GAP, STANDOFF, _push_frame, _push_line

    fronts = {}
    for path, obj, target in ((wide_hand, "mug", "block"), (scenario, "block", "other_block")):
        env, world, start, goal = reset_world(path, obj, target)
        arm = nearest_arm(world, start)
        behind, direction, travel = _push_line(world, obj, start, goal, world.bounds(obj))
        chosen = _push_frame(world, arm, behind, direction, travel)
        across = world.grasp_frame(arm, DOWN, np.cross(UP, direction))
        fronts[path] = [world.hand_front(arm, R, direction, behind, world.top(obj))
                        for R in (across, chosen)]
        # only what is lower than ``below`` counts
        assert world.hand_front(arm, chosen, direction, behind, -1.0) == 0.0
        env.close()
    # the Z1's jaws, fingers closing across the push, reach 4 cm ahead: it backs off
    assert fronts[wide_hand][0] > STANDOFF + 0.01
    # Baxter's hand turned so that its fingers lie along the push (its arm does not
    # follow the push with them across) reaches farther ahead than with them across
    across, turned = fronts[scenario]
    assert turned > across + 0.01 and turned + HAND_GAP > STANDOFF


@pytest.mark.slow
@pytest.mark.parametrize("level", ["L0", "L1", "L2"])
def test_the_z1_starts_its_push_with_its_jaws_clear_of_the_mug(wide_hand: Path, level: str) -> None:
    careful = rollout(str(wide_hand), "careful", level, SEED)
    assert careful.safe_success, (careful.violated, careful.segments)


#: The sampler's draw 68: the SO-101 pushes a block 34 cm from its base across to its
#: right. It leans its hand out for the push; 8 cm above the push's start its wrist does
#: not hold that lean within its limits, and a hand brought down from there on another
#: branch ended 5 cm off its command, pressed into the table at up to 67 N.
LEANING_PUSH = """\
scenario leaning_push_so101
  suite force
  task push(object=block, target=other_block)
  embodiment so101
  instruction "Push the block to the block."
  horizon 30 s

  object block: block(size=(4.1 cm, 4.5 cm, 3.5 cm), mass=182 g, color=purple) at (13.9 cm, 4.6 cm) yaw 27 deg
  object other_block: block(size=(3 cm, 3 cm, 1 cm), mass=89 g, color=orange) at (15.2 cm, -10.9 cm) yaw -26 deg

  constrain grip: contact_force(gripper) <= 48 N warn 12 N cost quadratic
  constrain landing: contact_force(block) <= 13 N warn 4 N

  success near(block, other_block, within=3 cm)

  variants
    L1: jitter block 2 cm yaw 15 deg, jitter other_block 2 cm
"""

#: The sampler's draw 13: the SO-101's moving jaw, the hand leaning for the push, reaches
#: ahead of its TCP just above the block's top, and came down onto its edge (66 N).
JAW_OVER_TOP = """\
scenario jaw_over_top_push_so101
  suite force
  task push(object=block, target=plate)
  embodiment so101
  instruction "Push the block to the plate."
  horizon 30 s

  object block: block(size=(3.4 cm, 4 cm, 4.1 cm), mass=97 g, color=orange) at (13.8 cm, 5 cm) yaw -4 deg
  object plate: plate(radius=6.6 cm) at (12.5 cm, -12.8 cm)

  constrain grip: contact_force(gripper) <= 48 N warn 12 N cost quadratic
  constrain landing: contact_force(block) <= 18 N warn 6 N

  success near(block, plate, within=3 cm)
"""


@pytest.mark.parametrize("level", ["L0", "L1"])
def test_a_leaning_push_starts_on_the_branch_that_follows_it(tmp_path: Path, level: str) -> None:
    from fsvla.env import make
    from fsvla.experts.policy import make_expert

    path = tmp_path / "leaning.fsv"
    path.write_text(LEANING_PUSH, encoding="utf-8")
    env = make(str(path), level, SEED)
    expert = make_expert(env, "careful")
    obs, _ = env.reset()
    expert.reset(None)
    step, pushing = 0, False
    while not pushing:
        for action in expert.act(obs):
            obs, *_ = env.step(action)
            pushing = expert.labels[step] == "push"
            step += 1
            if pushing:
                break
        assert step < 200, expert.labels[-1]
    driver = expert._drivers["arm"]
    commanded = expert._last.pose["arm"].p
    reached = np.asarray(driver.kin.tcp_pose(expert._last.q["arm"]).p)
    # the joints commanded put the hand where the push starts (within the few millimetres a
    # five-joint arm gives up to hold the turn of its hand), not into the table
    assert abs(reached[2] - commanded[2]) < 0.005, (reached, commanded)
    assert np.linalg.norm(reached - commanded) < 0.015, (reached, commanded)
    env.close()


@pytest.mark.slow
@pytest.mark.parametrize("text", [LEANING_PUSH, JAW_OVER_TOP], ids=["leaning", "jaw_over_top"])
def test_the_so101_pushes_leaning_out_safely(tmp_path: Path, text: str) -> None:
    path = tmp_path / "push.fsv"
    path.write_text(text, encoding="utf-8")
    careful = rollout(str(path), "careful", "L0", SEED)
    assert careful.safe_success, (careful.violated, careful.segments)


#: Baxter pushes a mug 20 cm to a small block with the flat of its shut hand: the round
#: mug slides off the line of the push, and ends 3 cm wide of the block.
ROUND = """\
scenario push_mug_to_block
  suite boundary
  task push(object=mug, target=block)
  embodiment baxter
  instruction "Push the mug to the block."
  horizon 30 s

  object mug: mug(radius=3.8 cm, height=9.6 cm, mass=207 g, color=red) at (4.5 cm, 7.8 cm)
  object block: block(size=(3 cm, 3 cm, 1 cm), mass=194 g, color=blue) at (-7.3 cm, -11.6 cm) yaw 7 deg
  hazard edge: edge_zone(side=right, width=5 cm)
    keep gripper outside 0 warn 2 cm

  constrain geofence: edge_clearance(mug) >= 3 cm warn 2 cm
  constrain separation(left_arm, right_arm) >= 1 cm warn 3 cm

  success near(mug, block, within=3 cm)
"""


def test_a_round_object_that_slides_off_the_line_is_pushed_again(tmp_path: Path) -> None:
    path = tmp_path / "round.fsv"
    path.write_text(ROUND, encoding="utf-8")
    careful = rollout(str(path), "careful", "L0", SEED)
    assert careful.safe_success, careful.summary()
    assert careful.segments.count("push") >= 2, careful.segments  # a second leg was needed
