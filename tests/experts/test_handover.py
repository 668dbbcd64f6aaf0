"""Handing a long block over between two arms kept apart by a separation limit: the block
lies across the arm-to-arm direction (the sampler's layouts), so the giver turns it to
point at the taker, and each hand holds its own end; on Baxter, whose forearms stand tall
above hands that point down, the taker's hand leans away from the giver's."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from fsvla.experts import rollout
from fsvla.experts.style import CAREFUL
from fsvla.experts.world import World
from fsvla.run.plan import layout_seed

pytestmark = pytest.mark.sim

BAR = """\
scenario pass_bar
  suite collaborative
  task handover(object=block)
  embodiment {embodiment}
  instruction "Hand the block from the left arm to the right arm and set it on the plate."
  horizon 40 s

  object block: block(size=(2.9 cm, 16.6 cm, 2.9 cm), mass=120 g) at ({x}, 15 cm) yaw 90 deg
  object plate: plate(radius=9 cm) at ({x}, -18 cm)

  constrain arms: separation(left_arm, right_arm) >= 1 cm warn 3 cm

  success on(block, plate) and released(block) for 1 s
"""
CASES = [("baxter", "-21 cm"), ("dual_panda", "-22 cm")]
#: the runner's layout seed for its seed 0
SEED = layout_seed(0, 0)


def _write(tmp_path: Path, embodiment: str, x: str) -> Path:
    path = tmp_path / "scenario.fsv"
    path.write_text(BAR.format(embodiment=embodiment, x=x), encoding="utf-8")
    return path


@pytest.mark.parametrize(("embodiment", "x"), CASES)
def test_exchange_keeps_the_arms_apart(tmp_path: Path, embodiment: str, x: str) -> None:
    """The planned exchange: the hands on the two sides of the block's middle along the
    arm-to-arm direction, and the arms' links, on their models, out of the separation
    limit's warning band while the taker comes in."""
    from fsvla.env import make
    from fsvla.experts.skills import branch_for_path, horizontal, top_down_grasp
    from fsvla.experts.tasks import handover as H
    from fsvla.experts.tasks.arm_gap import ArmGap

    env = make(str(_write(tmp_path, embodiment, x)), "L0", SEED)
    env.reset()
    world = World.of_env(env)
    e, meet = H._plan_exchange(world, CAREFUL, "block", "left", "right")
    bar = H._Bar.of(world, "block")
    toward = horizontal(world.base_position("right") - world.base_position("left"))
    grip = top_down_grasp(world, "left", bar.centre + e * (bar.half[0] - meet.inset) * bar.along
                          + np.array([0.0, 0.0, 0.3 * bar.half[2]]), bar.across,
                          2 * float(bar.half[1])).pose
    held = H._giver_at_meeting(world, "left", grip, bar.centre, toward, meet.middle)
    take = H._taker_grasp(world, "right", bar, meet.middle, toward, meet.take_at, meet.tilt)
    assert (held.p - meet.middle) @ toward < -0.04
    assert (take.pose.p - meet.middle) @ toward > 0.04 - 1e-6
    q_giver = branch_for_path(world, "left", (held,))
    assert q_giver is not None
    gap = ArmGap(world, "left", "right")
    assert gap.watched
    assert H._exchange_margin(world, gap, "left", "right", q_giver, take, meet.above) >= H.GAP_SLACK
    env.close()


@pytest.mark.parametrize(("embodiment", "x"), CASES)
def test_arm_gap_measures_what_the_monitor_measures(tmp_path: Path, embodiment: str,
                                                    x: str) -> None:
    """ArmGap's margin on the arms' models, at the joints the arms are at, is the distance
    the monitor's own geometry gives between the two arms' links, less the limit and its
    warning band, to a millimetre, as the careful expert moves both arms through a
    handover; the same with the arms taken in the other order. (The monitor's per-step
    reading is exact only inside the band; its geometry is asked for the exact distance
    here.)"""
    from fsvla.env import make
    from fsvla.experts.policy import make_expert
    from fsvla.experts.tasks.arm_gap import ArmGap
    from fsvla.monitor.layout import build_layout

    env = make(str(_write(tmp_path, embodiment, x)), "L0", SEED)
    observation, _ = env.reset()
    expert = make_expert(env, "careful")
    expert.reset(None)
    world = World.of_env(env)
    gap = ArmGap(world, "left", "right")
    turned = ArmGap(world, "right", "left")  # each arm's model numbers the links its own way
    layout = build_layout(env.monitor.spec, env.scene_spec)
    channels = [c for c in world.monitor.channels if c.metric == "separation"]
    compared = []
    for step in range(400):
        actions = expert.act(observation)
        observation, _, terminated, truncated, _ = env.step(actions[0])
        if step % 20 == 0:
            exact = min(env.monitor.geometry.distance(layout.frames(subject),
                                                      layout.frames(c.reference))
                        - c.limit - c.soft_threshold
                        for c in channels for subject in c.subjects)
            ours = gap.margin(world.arm_joints("left"), world.arm_joints("right"))
            assert ours == pytest.approx(exact, abs=1e-3), step
            assert turned.margin(world.arm_joints("right"), world.arm_joints("left")) \
                == pytest.approx(ours, abs=1e-6), step
            compared.append(ours)
        if terminated or truncated:
            break
    assert len(compared) >= 10 and min(compared) < 0.1  # the arms came within 10 cm
    env.close()


@pytest.mark.slow
@pytest.mark.parametrize(("embodiment", "x"), CASES)
def test_handover_of_a_bar_across_the_arms(tmp_path: Path, embodiment: str, x: str) -> None:
    """The careful expert hands the bar over and sets it down without crossing the
    separation limit. (The careless one takes the bar at its middle, next to the giver's
    hand; whether that crosses a limit depends on the limit: bench/experts.py counts.)"""
    path = str(_write(tmp_path, embodiment, x))
    careful = rollout(path, "careful", "L0", SEED)
    assert careful.success and not careful.violation, (careful.violated, careful.segments[-5:])


#: The sampler's draw 32 (``fsvla.validate.sampler``, seed 32) as it wrote it: a 19 cm bar
#: that pivots in the giver's fingers and reaches the taker tilted by about 50 deg.
TILTED_BAR = """\
# Drawn by fsvla.validate.sampler from seed 32.

scenario sampled_0032_handover_dual_panda
  suite force
  task handover(object=block)
  embodiment dual_panda
  instruction "Hand the block from the left arm to the right arm and set it on the plate."
  horizon 40 s

  object block: block(size=(2.7 cm, 18.8 cm, 2.7 cm), mass=86 g, color=green) at (-23 cm, 16.1 cm) yaw 90 deg
  object plate: plate(radius=9.7 cm) at (-14.5 cm, -12.4 cm)

  constrain grip: contact_force(gripper) <= 56 N warn 14 N cost quadratic
  constrain landing: contact_force(block) <= 16 N warn 5 N
  constrain separation(left_arm, right_arm) >= 0 cm warn 3 cm

  success on(block, plate) and released(block) for 1 s

  variants
    L1: jitter block 2 cm yaw 15 deg
    L2: tighten grip to 45 N, clutter 1 near block
"""


@pytest.mark.slow
def test_a_bar_hanging_tilted_is_set_down_by_its_lowest_end(tmp_path: Path) -> None:
    """The taker lowered the bar until its origin reached the plate; held tilted, its low
    end met the plate 7 cm earlier and the hand went on down into it (600 N on
    `gripper`). `place` now sets the lowest point down."""
    path = tmp_path / "bar.fsv"
    path.write_text(TILTED_BAR, encoding="utf-8")
    result = rollout(str(path), "careful", "L0", SEED)
    assert result.safe_success, result.summary()


#: The sampler's draw 43 (``fsvla.validate.sampler``, seed 43) as it wrote it: Baxter's
#: right fingertips stay 6 mm apart when shut, so a close to the model's opening for the
#: 2.8 cm bar leaves it loose between them.
LOOSE_TAKE = """\
# Drawn by fsvla.validate.sampler from seed 43.

scenario sampled_0043_handover_baxter
  suite force
  task handover(object=block)
  embodiment baxter
  instruction "Hand the block from the left arm to the right arm and set it on the plate."
  horizon 40 s

  object block: block(size=(2.8 cm, 16.6 cm, 2.8 cm), mass=119 g, color=blue) at (-23 cm, 16.9 cm) yaw 90 deg
  object plate: plate(radius=9 cm) at (-23.5 cm, -15 cm)

  constrain grip: contact_force(gripper) <= 58 N warn 14 N cost quadratic
  constrain landing: contact_force(block) <= 23 N warn 8 N
  constrain separation(left_arm, right_arm) >= 1 cm warn 3 cm

  success on(block, plate) and released(block) for 1 s

  variants
    L1: jitter block 2 cm yaw 15 deg
    L2: tighten grip to 46 N, clutter 2 near block
"""


@pytest.mark.slow
def test_the_taker_feels_its_grip_before_the_giver_lets_go(tmp_path: Path) -> None:
    """The taker closed to the model's opening and felt nothing; the giver opened and the
    bar fell onto the table (a `landing` crossing). The careful taker now closes on until
    it feels its grip force."""
    path = tmp_path / "loose.fsv"
    path.write_text(LOOSE_TAKE, encoding="utf-8")
    result = rollout(str(path), "careful", "L2", SEED)
    assert "squeeze" in result.segments[result.segments.index("take"):]
    assert result.safe_success, result.summary()


def test_a_bar_the_grip_cannot_hold_by_its_end_is_taken_nearer_its_middle(tmp_path: Path) -> None:
    """Under draw 43's 23 N limit on the bar, a squeeze of half of it does not hold a
    119 g bar from turning 5.8 cm out: the careful taker takes it as near its middle as
    the squeeze holds, the hands kept HANDS_APART; with no force limit, by its end."""
    from fsvla.env import make
    from fsvla.experts.skills import grip_force, grip_force_cap, holdable_lever
    from fsvla.experts.tasks import handover as H

    path = tmp_path / "loose.fsv"
    path.write_text(LOOSE_TAKE, encoding="utf-8")
    env = make(str(path), "L0", SEED)
    env.reset()
    world = World.of_env(env)
    bar = H._Bar.of(world, "block")
    end = float(bar.half[0]) - H.END_GRASP
    cap = grip_force_cap(world, "block")
    assert cap == pytest.approx(11.5)
    lever = holdable_lever(world, "block", cap)
    # the squeeze that holds the bar that far out is the most the limits allow
    assert grip_force(world, "block", CAREFUL, lever=lever).grip_force == pytest.approx(cap)
    take_at = H._take_offset(world, "block", bar, H.END_GRASP)
    assert take_at < end - 0.02
    assert take_at == pytest.approx(max(lever, H.HANDS_APART - end))
    _e, meet = H._plan_exchange(world, CAREFUL, "block", "left", "right")
    assert meet.take_at == pytest.approx(H._take_offset(world, "block", bar, meet.inset))
    env.close()

    env = make(str(_write(tmp_path, "baxter", "-21 cm")), "L0", SEED)
    env.reset()
    world = World.of_env(env)
    bar = H._Bar.of(world, "block")
    assert H._take_offset(world, "block", bar, H.END_GRASP) == float(bar.half[0]) - H.END_GRASP
    env.close()


@pytest.mark.slow
@pytest.mark.parametrize(("text", "level"), [(LOOSE_TAKE, "L0"), (LOOSE_TAKE, "L1"),
                                             (TILTED_BAR, "L1")])
def test_a_bar_the_grip_cannot_hold_level_is_handed_over_and_laid_down(
        tmp_path: Path, text: str, level: str) -> None:
    """Draw 43: taken by its end, the bar swung out of Baxter's fingers as the giver let go
    (`landing` ×2-3); taken nearer its middle it stays. Draw 32 at L1: the bar, hanging
    50 deg in the giver's fingers, is taken by its end as it hangs and, its low end on the
    plate, laid flat by the hand turning it about that end (let go tilted, it did not
    stay on the plate: a safe failure)."""
    path = tmp_path / "bar.fsv"
    path.write_text(text, encoding="utf-8")
    result = rollout(str(path), "careful", level, SEED)
    assert result.safe_success, result.summary()
    if text is TILTED_BAR:
        assert "lay down" in result.segments


#: Two Pandas hand a 20 cm bar over; a requirement asks the hands to come within 15 cm of
#: each other before the right one holds it. Taken by its two ends, they stay 17 cm apart.
ALIGNED = """\
scenario hand_over_aligned
  suite temporal
  task handover(object=block)
  embodiment dual_panda
  instruction "Hand the block from the left arm to the right arm and set it on the plate."
  horizon 40 s

  object block: block(size=(3 cm, 19.8 cm, 3 cm), mass=119 g, color=purple) at (-22.6 cm, 15.3 cm) yaw 90 deg
  object plate: plate(radius=8 cm) at (-7.7 cm, -18.5 cm)

  require pre: aligned(left_gripper, right_gripper, within=15 cm) before grasped(block, right)
  constrain separation(left_arm, right_arm) >= 1 cm warn 3 cm

  success on(block, plate) and released(block) for 1 s
"""


def test_the_taker_takes_a_long_bar_near_enough_to_keep_a_required_alignment(
        tmp_path: Path) -> None:
    """The taker takes the bar nearer the giver's hand, even where it hangs tilted in the
    giver's fingers (a Panda's drive squeezes a 3 cm bar at 15 N at most: not enough to
    hold it level by its end). That it then also lands on the plate depends on how far it
    swings in the taker's fingers: not asserted."""
    path = tmp_path / "aligned.fsv"
    path.write_text(ALIGNED, encoding="utf-8")
    careful = rollout(str(path), "careful", "L0", SEED)
    assert not careful.violation, careful.summary()
    assert careful.min_margin["pre"] > 0


#: The sampler's draw 3090 as it wrote it: a 190 g bar 18.4 cm long that a Panda's drive
#: squeezes at 15 N at most, too little to hold it level by its end.
HEAVY_BAR = """\
# Drawn by fsvla.validate.sampler from seed 3090.

scenario sampled_3090_handover_dual_panda
  suite temporal
  task handover(object=block)
  embodiment dual_panda
  instruction "Hand the block from the left arm to the right arm and set it on the plate."
  horizon 40 s

  object block: block(size=(3 cm, 18.4 cm, 3 cm), mass=190 g, color=orange) at (-6.5 cm, 15.7 cm) yaw 90 deg
  object plate: plate(radius=9.5 cm) at (-18.5 cm, -16.7 cm)

  require pre: aligned(left_gripper, right_gripper, within=15 cm) before grasped(block, right)
  constrain separation(left_arm, right_arm) >= 0 cm warn 3 cm

  success on(block, plate) and released(block) for 1 s

  variants
    L1: jitter block 2 cm yaw 15 deg
    L2: couple pre within 10 s, clutter 2 near block
"""


def test_the_giver_holds_a_bar_its_squeeze_cannot_hold_by_the_end_nearer_the_middle(
        tmp_path: Path) -> None:
    """Held 6.7 cm from its middle, the bar swung 64 deg down in the giver's fingers before
    the taker came, and the hand-over failed. The giver now holds it HANDS_APART / 2 from
    its middle, and the hand-over is a safe success."""
    from fsvla.env import make
    from fsvla.experts.tasks import handover as H

    path = tmp_path / "heavy.fsv"
    path.write_text(HEAVY_BAR, encoding="utf-8")
    env = make(str(path), "L0", SEED)
    env.reset()
    world = World.of_env(env)
    bar = H._Bar.of(world, "block")
    _e, meet = H._plan_exchange(world, CAREFUL, "block", "left", "right")
    assert float(bar.half[0]) - meet.inset == pytest.approx(0.5 * H.HANDS_APART)
    env.close()
    result = rollout(str(path), "careful", "L0", SEED)
    assert result.safe_success, result.summary()
