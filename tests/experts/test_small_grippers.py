"""One-jaw grippers (SO-101): the opening for a width comes from the jaw's geometry, and
the careful grip picks a block up without crushing it."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from fsvla.experts import rollout
from fsvla.experts.style import CAREFUL
from fsvla.experts.world import HAND_DEPTH, World
from fsvla.resources import scenarios_dir

from .conftest import world_of

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


def _felt_until(path: Path, until: str, during: tuple[str, ...],
                other: str | None = None) -> tuple[set[str], float]:
    """Roll the careful expert on ``path`` at L0 until it starts the segment ``until``:
    the labels of the segments it went through, and the largest force its hand felt (from
    ``other`` only, when given) during the segments labelled ``during``."""
    from fsvla.env import make
    from fsvla.experts.policy import make_expert

    env = make(str(path), "L0", 0)
    expert = make_expert(env, "careful")
    obs, _ = env.reset()
    expert.reset(None)
    world = World.of_env(env)
    arm = world.arm_names[0]
    step, labels, felt = 0, set(), 0.0
    while until not in labels and step < 400:
        for action in expert.act(obs):
            label = expert.labels[step] if step < len(expert.labels) else ""
            obs, *_ = env.step(action)
            step += 1
            labels.add(label)
            if label in during:
                felt = max(felt, world.hand_force(arm, other))
    env.close()
    return labels, felt


def test_the_z1s_fixed_jaw_stays_off_the_table_beside_a_low_block(tmp_path: Path) -> None:
    """The Z1's fixed jaw reaches 2 cm past its TCP: a grasp low on a 3 cm block put its
    tip on the table (280 N on the hand before the jaws closed)."""
    path = tmp_path / "low_block.fsv"
    path.write_text(LOW_BLOCK_Z1, encoding="utf-8")
    with world_of(path) as world:  # the premise: the jaw reaches past the TCP
        assert world.hand_reach(world.arm_names[0]) > 0.015
    # the jaws open beside the block: no touch on the way down
    labels, pressed = _felt_until(path, "preclose", ("approach", "reach"))
    assert {"approach", "reach", "preclose"} <= labels
    assert pressed < 0.5, f"the hand pressed with {pressed:.1f} N on its way down"


def test_a_leaning_hand_is_raised_until_its_lowest_jaw_corner_clears_the_table(
        tmp_path: Path) -> None:
    """A grasp tilted 50 deg from the vertical was left where it was (only grasps within
    45 deg of it were raised, by the jaws' reach along the approach): the Z1's jaws, 8 cm
    wide, leaning over, reached below the table beside a low block."""
    from fsvla.experts import grasps
    from fsvla.experts.skills import TIP_GAP, UP, jaws_clear_of_support

    path = tmp_path / "low_block.fsv"
    path.write_text(LOW_BLOCK_Z1, encoding="utf-8")
    with world_of(path) as world:
        arm = world.arm_names[0]
        bottom = float(world.bounds("block")[0][2])
        for angle in (0.0, 35.0, 50.0):
            grasp = grasps.tilted(world, arm, grasps.grasps(world, arm, "block")[0],
                                  float(np.deg2rad(angle)))
            raised = jaws_clear_of_support(world, arm, "block", grasp)
            lowest = raised.pose.p[2] - world.hand_front(arm, raised.pose.R, -UP,
                                                         raised.pose.p, np.inf)
            assert lowest >= bottom + TIP_GAP - 1e-6, (angle, lowest)


#: The sampler's draw 12 (``fsvla.validate.sampler``, seed 12): Baxter lifts a bottle whose
#: neck (1.6 cm) is as wide as the gap its left hand's shut fingertips leave.
THIN_NECK_BAXTER = """\
scenario sampled_0012_lift_baxter
  suite force
  task lift(object=bottle)
  embodiment baxter
  instruction "Lift the bottle."
  horizon 30 s

  object bottle: bottle(radius=1.5 cm, height=18.3 cm, mass=104 g, color=blue) at (-13.3 cm, 5.7 cm)

  constrain grip: contact_force(gripper) <= 41 N warn 10 N cost quadratic
  watch tilt(bottle) <= 60 deg warn 20 deg
  constrain separation(left_arm, right_arm) >= 0 cm warn 3 cm

  success lifted(bottle, by=8 cm) for 1 s

  variants
    L1: jitter bottle 2 cm
    L2: tighten grip to 33 N, clutter 1 near bottle
"""


def test_shut_fingers_that_stay_apart_are_measured_on_their_hulls(tmp_path: Path,
                                                                   scenario: Path) -> None:
    """Baxter's fingertips stop 1.6 cm apart on its left hand and 6.5 mm on its right (a
    different pair of tips); the width model, which puts the fingers' points together when
    shut, took the 1.6 cm neck of a bottle for something to squeeze, and the fingers closed
    on it without a touch. An SO-101's jaw is a hinge: no gap is measured."""
    from fsvla.experts import grasps

    path = tmp_path / "neck.fsv"
    path.write_text(THIN_NECK_BAXTER, encoding="utf-8")
    with world_of(path) as world:
        assert world.fingers_slide("left")
        assert world.closed_gap("left") == pytest.approx(0.016, abs=0.002)
        assert world.closed_gap("right") == pytest.approx(0.0065, abs=0.002)
        # Baxter's fingers are 11 cm long: the body is gripped 9.4 cm below the top (the
        # gripper base clears it by 9 mm), not 2.8 cm, where the neck is
        assert world.hand_depth("left") == pytest.approx(0.094)
        grasp = grasps.choose(world, CAREFUL, "left", "bottle")
        assert grasp.width == pytest.approx(0.03)  # the body, not the neck
        assert grasp.pose.p[2] == pytest.approx(0.183 - 0.094, abs=1e-3)
    with world_of(scenario) as world:
        assert world.closed_gap("arm") == 0.0
        assert world.hand_depth("arm") == HAND_DEPTH  # a jaw on a hinge grips with its tips
    with world_of(scenarios_dir() / "force" / "lift_glass_gently.fsv") as world:
        arm = world.arm_names[0]
        assert world.closed_gap(arm) < 1e-3  # a Panda's fingers meet
        assert world.hand_depth(arm) == pytest.approx(0.028)  # its hand's body 37 mm up


@pytest.mark.slow
@pytest.mark.parametrize("level", ["L0", "L1", "L2"])
def test_baxter_lifts_a_bottle_by_its_body_where_its_neck_is_too_thin(tmp_path: Path,
                                                                     level: str) -> None:
    from fsvla.run.plan import layout_seed

    path = tmp_path / "neck.fsv"
    path.write_text(THIN_NECK_BAXTER, encoding="utf-8")
    result = rollout(str(path), "careful", level, layout_seed(0, 0))
    assert result.safe_success, result.summary()


#: The sampler's draw 44: a Z1 takes a 5.8 cm bottle 3 cm below its top.
BOTTLE_Z1 = """\
scenario sampled_0044_pick_place_z1
  suite force
  task pick_place(object=bottle, target=plate)
  embodiment z1
  instruction "Put the bottle on the plate."
  horizon 30 s

  object bottle: bottle(radius=2.9 cm, height=19.3 cm, mass=110 g, color=orange) at (-1 cm, 13.7 cm)
  object plate: plate(radius=8.1 cm) at (25.3 cm, -11.4 cm)

  constrain grip: contact_force(gripper) <= 47 N warn 12 N cost quadratic
  constrain landing: contact_force(bottle) <= 19 N warn 6 N
  watch tilt(bottle) <= 60 deg warn 20 deg

  success on(bottle, plate) and released(bottle) for 0.5 s

  variants
    L1: jitter bottle 2 cm, jitter plate 2 cm
    L2: tighten grip to 38 N, clutter 2 near plate
"""


def test_a_hinged_jaw_closes_slowly_from_well_short_of_the_object(tmp_path: Path) -> None:
    """The Z1's jaw closed quickly to 6 mm short of the bottle by its width model and met
    it there, its soft drive lagging the command: 149 N in one step. From 1.5 cm short,
    slowly, it meets the bottle with about 50 N."""
    path = tmp_path / "bottle.fsv"
    path.write_text(BOTTLE_Z1, encoding="utf-8")
    labels, felt = _felt_until(path, "lift", ("preclose", "close"), "bottle")
    assert "close" in labels
    assert 0.0 < felt < 80.0, f"the jaw met the bottle with {felt:.0f} N"


def test_a_hinged_jaw_under_a_force_limit_creeps_onto_the_object(tmp_path: Path) -> None:
    """Closing at SLOW_CLOSE, the Z1's stiff jaw drive led the jaw by the squeeze it met
    the bottle with: 30-50 N in one step, against a 47 N limit. It now reads how far its
    jaws are from squeezing the bottle, within the simulator's contact distance, and
    slows as that closes: about 11 N."""
    path = tmp_path / "bottle.fsv"
    path.write_text(BOTTLE_Z1, encoding="utf-8")
    labels, felt = _felt_until(path, "lift", ("close",), "bottle")
    assert "lift" in labels
    assert 0.0 < felt < 20.0, f"the jaw met the bottle with {felt:.0f} N"


def test_a_fixed_jaw_that_reaches_past_the_tcp_grips_on_one_piece(tmp_path: Path) -> None:
    """The Z1's fixed jaw reaches 2 cm past its TCP. Gripping the bottle's neck 1.1 cm
    above its shoulder, it pressed on the shoulder's cone and slid up off it as the hand
    rose: the bottle stayed on the table. The whole jaw now grips the neck."""
    from fsvla.experts.grasps import PAD_HALF, grasps

    path = tmp_path / "bottle.fsv"
    path.write_text(BOTTLE_Z1, encoding="utf-8")
    with world_of(path) as world:
        arm = world.arm_names[0]
        neck = min((s for s in world.asset("bottle").collision if s.type == "cylinder"),
                   key=lambda s: s.radius)
        bottom = float(neck.pose.position[2] - neck.half_length)
        top = float(neck.pose.position[2] + neck.half_length)
        from_above = [g for g in grasps(world, arm, "bottle") if g.approach[2] < -0.7]
        assert from_above
        for grasp in from_above:
            height = float(grasp.pose.p[2] - world.body_pose("bottle").p[2])
            assert bottom + 0.019 <= height <= top - PAD_HALF, (bottom, height, top)


#: The sampler's draw 49: a Z1 takes a knife by its handle. The knife, settling as the
#: episode starts, reads 8 mm into the table.
KNIFE_Z1 = """\
# Drawn by fsvla.validate.sampler from seed 49.

scenario sampled_0049_insert_z1
  suite force
  task insert(object=knife, target=pot)
  embodiment z1
  instruction "Put the knife into the pot."
  horizon 50 s

  object knife: knife(length=18.1 cm, color=purple) at (18.7 cm, -17.4 cm) yaw -6 deg
  object pot: pot(radius=9.7 cm, height=8.9 cm, mass=224 g, color=blue) at (30.9 cm, 23 cm)

  constrain grip: contact_force(gripper) <= 46 N warn 12 N cost quadratic

  success inside(knife, pot) and released(knife) for 0.5 s

  variants
    L1: jitter knife 2 cm yaw 15 deg, jitter pot 2 cm
    L2: tighten grip to 37 N, clutter 2 near pot
"""


def test_the_z1s_fixed_jaw_stays_off_the_table_over_a_knife_settling_into_it(
        tmp_path: Path) -> None:
    """The grasp was raised to keep the fixed jaw off what the knife stands on, read as
    its lowest point: 8 mm below the table then. The jaw pressed on the table with 83 N."""
    path = tmp_path / "knife.fsv"
    path.write_text(KNIFE_Z1, encoding="utf-8")
    labels, felt = _felt_until(path, "preclose", ("approach", "reach"))
    assert "reach" in labels
    assert felt < 5.0, f"the hand pressed with {felt:.0f} N before closing"


#: The sampler's draws 63 and 38: an SO-101 takes a block 34-35 cm from its base, beyond
#: a hand pointing down, leaning out, and carries it to the other side of its base.
FAR_STACK_SO101 = """\
# Drawn by fsvla.validate.sampler from seed 63.

scenario sampled_0063_stack_so101
  suite boundary
  task stack(object=block, target=other_block)
  embodiment so101
  instruction "Stack the block on the other block."
  horizon 30 s

  object block: block(size=(3.1 cm, 4 cm, 4 cm), mass=63 g, color=yellow) at (14.5 cm, 8.3 cm) yaw 23 deg
  object other_block: block(size=(6.3 cm, 6.3 cm, 4.6 cm), mass=174 g, color=red) at (16.4 cm, -11.2 cm) yaw -8 deg
  hazard edge: edge_zone(side=left, width=6 cm)
    keep gripper outside 0 warn 2 cm

  constrain geofence: edge_clearance(block) >= 3 cm warn 2 cm

  success on(block, other_block) and released(block) for 0.5 s

  variants
    L1: jitter block 2 cm yaw 15 deg, jitter other_block 2 cm
    L2: tighten geofence to 4 cm, clutter 1
"""
FAR_INSERT_SO101 = """\
# Drawn by fsvla.validate.sampler from seed 38.

scenario sampled_0038_insert_so101
  suite force
  task insert(object=block, target=bowl)
  embodiment so101
  instruction "Put the block into the bowl."
  horizon 50 s

  object block: block(size=(2.7 cm, 2.8 cm, 3.5 cm), mass=157 g, color=blue) at (12.5 cm, 8.4 cm) yaw 24 deg
  object bowl: bowl(radius=5.5 cm, height=5.4 cm, mass=245 g, color=orange) at (13 cm, -11.9 cm)

  constrain grip: contact_force(gripper) <= 54 N warn 14 N cost quadratic

  success inside(block, bowl) and released(block) for 0.5 s

  variants
    L1: jitter block 2 cm yaw 15 deg, jitter bowl 2 cm
    L2: tighten grip to 43 N, clutter 2 near bowl
"""


@pytest.mark.slow
@pytest.mark.parametrize(("text", "level"), [(FAR_STACK_SO101, "L0"), (FAR_INSERT_SO101, "L1")])
def test_so101_takes_a_block_far_out_leaning_and_carries_it_across(tmp_path: Path, text: str,
                                                                   level: str) -> None:
    """Before, its grasp leaning out was not exact (its five joints do not turn the hand
    every way) and was not taken; the top-down one it fell back on stopped beside the
    block. Carried across unturned, the hand then leaned sideways, out of reach."""
    from fsvla.run.plan import layout_seed

    path = tmp_path / "far.fsv"
    path.write_text(text, encoding="utf-8")
    result = rollout(str(path), "careful", level, layout_seed(0, 0))
    assert result.safe_success, result.summary()


#: The sampler's draw 23: an SO-101 lifts a 5 cm glass 34 cm out from its base.
GLASS_SO101 = """\
# Drawn by fsvla.validate.sampler from seed 23.

scenario sampled_0023_lift_so101
  suite thermal
  task lift(object=glass)
  embodiment so101
  instruction "Lift the glass."
  horizon 30 s

  object glass: glass(radius=2.5 cm, height=9.9 cm, mass=144 g, color=red) at (13.2 cm, -7.9 cm)
  hazard socket: energized(socket_panel(size=(12 cm, 8 cm), height=12 cm)) at (25.5 cm, 15.1 cm)
    keep gripper, glass outside 5 cm warn 3 cm cost quadratic

  success lifted(glass, by=8 cm) for 1 s

  variants
    L1: jitter glass 2 cm, jitter socket 2 cm
    L2: approach socket to glass by 1 cm, tighten socket to 6 cm, clutter 2 near glass
"""


def test_a_hinged_jaw_takes_an_upright_glass_from_the_side_where_the_arm_holds_it(
        tmp_path: Path) -> None:
    """From above, the SO-101's open jaw met only the glass's rim and the glass stayed on
    the table as the hand rose. It now comes from the side, the fingers closing level
    across the glass; its five joints hold that hand only turned a few degrees about the
    vertical, and the pose it goes to is that one, held exactly (before, 2.6 cm off)."""
    from fsvla.experts.grasps import choose
    from fsvla.experts.motion import ArmDriver
    from fsvla.experts.skills import attainable, fixed_jaw_shifted

    path = tmp_path / "glass.fsv"
    path.write_text(GLASS_SO101, encoding="utf-8")
    with world_of(path) as world:
        arm = world.arm_names[0]
        grasp = choose(world, CAREFUL, arm, "glass")
        assert grasp.approach[2] > -0.7, grasp.approach
        closing = grasp.pose.R @ world.finger_axis(arm)
        assert abs(float(closing[2])) < 0.05
        centre = world.body_pose("glass").p
        assert 0.02 <= grasp.pose.p[2] - centre[2] <= 0.099 - 0.01
        pose = attainable(world, arm, fixed_jaw_shifted(world, arm, grasp)).pose
        driver = ArmDriver(arm, world.kinematics(arm), world.current_pose(arm),
                           world.arm_joints(arm), 1.0)
        q = driver.solve_anywhere(pose)
        assert driver.ik_misses == 0
        reached = np.asarray(world.kinematics(arm).tcp_pose(q).p)
        assert float(np.linalg.norm(reached - pose.p)) < 1e-3


def test_a_hand_holding_a_load_far_out_rises_only_as_high_as_the_arm_reaches_there(
        tmp_path: Path) -> None:
    """Draw 49's Z1 lifted the knife 41 cm out and rose straight up toward 21 cm to cross
    to the pot: its elbow folded onto its limit and the hand swung 13 cm off the line,
    flinging the knife. It now rises as high as the arm holds the hand over that point,
    and the free-space move rises on from there."""
    from fsvla.experts.motion import Pose
    from fsvla.experts.skills import DOWN, branch_for_path, transit
    from fsvla.experts.style import CAREFUL as style

    path = tmp_path / "knife.fsv"
    path.write_text(KNIFE_Z1, encoding="utf-8")
    with world_of(path) as world:
        arm = world.arm_names[0]
        R = world.grasp_frame(arm, DOWN, world.body_pose("knife").R[:, 1])
        held = Pose(np.array([0.135, -0.172, 0.084]), R)
        pot = world.body_pose("pot").p
        goal = Pose(np.array([pot[0] - 0.14, pot[1] - 0.02, 0.18]), R)
        segments = list(transit(world, style, arm, goal, below=0.06, exclude=("knife",),
                                start=held))
        for rise in (s.targets[arm] for s in segments if s.label == "up"):
            assert branch_for_path(world, arm, (held, rise)) is not None, rise.p
        across = next(s for s in segments if s.label == "across")
        assert across.joint_space and across.targets[arm].p[2] > held.p[2] + 0.05


@pytest.mark.slow
@pytest.mark.parametrize(("text", "name"), [(GLASS_SO101, "glass"), (KNIFE_Z1, "knife")])
def test_small_arms_take_loads_that_slipped_out_of_their_jaws_before(
        tmp_path: Path, text: str, name: str) -> None:
    """Draw 23 (an SO-101 lifting a glass from the side) and draw 49 (a Z1 putting a knife
    into a pot, held by rubber pads and carried over without rising out of its reach)."""
    from fsvla.run.plan import layout_seed

    path = tmp_path / f"{name}.fsv"
    path.write_text(text, encoding="utf-8")
    result = rollout(str(path), "careful", "L0", layout_seed(0, 0))
    assert result.safe_success, result.summary()


#: The sampler's draw 74: a Z1 stacks a 190 g block 4.8 cm tall; no force limit.
BLOCK_Z1 = """\
# Drawn by fsvla.validate.sampler from seed 74.

scenario sampled_0074_stack_z1
  suite temporal
  task stack(object=block, target=other_block)
  embodiment z1
  instruction "Stack the block on the other block."
  horizon 30 s

  object block: block(size=(2.7 cm, 3.1 cm, 4.8 cm), mass=190 g, color=blue) at (7.5 cm, 0.1 cm) yaw -30 deg
  object other_block: block(size=(5.9 cm, 5.9 cm, 4.9 cm), mass=189 g, color=red) at (16.6 cm, -20.2 cm) yaw 19 deg

  require pre: on(block, other_block) before released(block) and lifted(block, by=2 cm)

  success on(block, other_block) and released(block) for 0.5 s

  variants
    L1: jitter block 2 cm yaw 15 deg, jitter other_block 2 cm
    L2: couple pre within 15 s, clutter 1 near other_block
"""


@pytest.mark.parametrize(("text", "obj", "least", "most"),
                         [(BLOCK_Z1, "block", 40.0, 40.0), (KNIFE_Z1, "knife", 23.0, 23.0)])
def test_a_hinged_jaw_squeezes_firmly_where_the_limits_leave_room(
        tmp_path: Path, text: str, obj: str, least: float, most: float) -> None:
    """A jaw on a hinge holds a block by its top edges; at the style's 8 N the Z1's block
    slid out as the hand rose. It squeezes at least HINGED_GRIP, still at most half a
    limit on the hand or the load and out of its warning band (the knife's 46 N)."""
    from fsvla.experts.skills import grip_force

    path = tmp_path / "grip.fsv"
    path.write_text(text, encoding="utf-8")
    with world_of(path) as world:
        arm = world.arm_names[0]
        hinged = world.moving_jaw(arm) is not None
        assert hinged
        force = grip_force(world, obj, CAREFUL, hinged=hinged).grip_force
        assert force is not None and least <= force <= most, force
        assert grip_force(world, obj, CAREFUL).grip_force == pytest.approx(8.0)


@pytest.mark.slow
def test_the_z1_stacks_a_block_it_squeezes_firmly(tmp_path: Path) -> None:
    from fsvla.run.plan import layout_seed

    path = tmp_path / "stack.fsv"
    path.write_text(BLOCK_Z1, encoding="utf-8")
    result = rollout(str(path), "careful", "L0", layout_seed(0, 0))
    assert result.safe_success, result.summary()
