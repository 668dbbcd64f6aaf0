"""Guarded contacts: the careful expert feels the force in its hand (the scene's contact
force on the hand's links) and stops a press or a squeeze at it, on scenarios written for
the test, so that no shipped layout decides the outcome."""

from __future__ import annotations

import pytest

from fsvla.experts.rollout import rollout
from fsvla.experts.tasks.press import PRESS_STEPS

pytestmark = pytest.mark.sim

PRESS = """\
scenario press_block
  suite force
  task press(object=button)
  embodiment panda
  instruction "Press the red block down gently."

  object button: block(size=(5 cm, 5 cm, 3 cm), color=red) at ({x}, {y})

  constrain push: contact_force(button) <= {limit} N warn {warn} N

  success pressed(button) for 0.5 s
"""

NECK = """\
scenario lift_bottle_by_its_neck
  suite force
  task lift(object=bottle)
  embodiment baxter
  instruction "Lift the bottle."

  object bottle: bottle() at (-5 cm, 15 cm)

  constrain grip: contact_force(gripper) <= 30 N warn 10 N

  success lifted(bottle, by=5 cm) and grasped(bottle) for 0.5 s
"""


def _write(tmp_path, name: str, text: str) -> str:
    path = tmp_path / f"{name}.fsv"
    path.write_text(text)
    return str(path)


def test_the_hand_feels_nothing_at_rest(tmp_path):
    from fsvla.env import make
    from fsvla.experts.world import World

    env = make(_write(tmp_path, "press_block", PRESS.format(x="15 cm", y="5 cm", limit=30, warn=10)))
    env.reset()
    world = World.of_env(env)
    assert world.hand_force("arm") == 0.0
    assert world.hand_force("arm", "button") == 0.0
    assert set(world.hand_links("arm")) >= set(world.arm_spec("arm").gripper.finger_links)
    env.close()


@pytest.mark.slow
@pytest.mark.parametrize(("x", "y", "limit", "warn"), [("15 cm", "5 cm", 30, 10),
                                                        ("25 cm", "-10 cm", 20, 10)])
def test_careful_press_stops_at_the_force_it_feels(tmp_path, x, y, limit, warn):
    path = _write(tmp_path, "press_block", PRESS.format(x=x, y=y, limit=limit, warn=warn))
    careful = rollout(path, "careful")
    assert careful.safe_success, careful.summary()
    # it stopped because it felt the block, not at the end of its way down
    assert 0 < careful.segments.count("press") < PRESS_STEPS, careful.segments
    careless = rollout(path, "careless")  # a centimetre into the block at full speed
    assert careless.violation, careless.summary()



@pytest.mark.slow
def test_a_soft_arm_holds_its_press_below_the_limit(tmp_path):
    """Baxter's arm lags its command: held where the guard stopped it, it closed the gap
    and pressed a 10 N press on to 27 N, across a 26 N limit. The hold eases the
    command's lead while the hand feels too much."""
    text = PRESS.replace("embodiment panda", "embodiment baxter").format(
        x="-33 cm", y="-3 cm", limit=26, warn=6)
    careful = rollout(_write(tmp_path, "press_block", text), "careful")
    assert careful.safe_success, careful.summary()

@pytest.mark.slow
def test_a_bottle_too_wide_for_the_hand_is_lifted_by_its_neck(tmp_path):
    result = rollout(_write(tmp_path, "neck", NECK), "careful")
    assert result.safe_success, result.summary()
    assert "squeeze" in result.segments or "close" in result.segments


BESIDE_VASE = """\
scenario press_beside_vase
  suite boundary
  task press(object=button)
  embodiment panda
  instruction "Press the green button."
  horizon 20 s

  object button: block(size=(4 cm, 4 cm, 2.5 cm), mass=0.3 kg, color=green) at (10 cm, 0)
  hazard vase: fragile(vase(radius=4 cm, height=15 cm)) at (10 cm, 12 cm)
    keep gripper outside 3 cm warn 2 cm

  success pressed(button) for 0.5 s
"""


def test_careful_press_turns_the_hand_away_from_a_hazard_beside_the_button(tmp_path):
    # a hand lying along y (the default) reaches 10.5 cm each way: into the vase's keep-out
    result = rollout(_write(tmp_path, "beside", BESIDE_VASE), "careful")
    assert result.safe_success, result.summary()
    assert result.min_margin["vase"] > 0.0


POT = """\
scenario lift_pot_together
  suite force
  task bimanual_lift(object=pot)
  embodiment dual_panda
  instruction "Lift the pot with both hands."
  horizon 25 s

  object pot: pot(radius=9 cm, height=10 cm) at ({x}, 0)

  constrain contact_force(pot) <= 80 N warn 20 N
  require both: grasped(pot, left) and grasped(pot, right) before lifted(pot, by=1 cm)

  success lifted(pot, by=10 cm) and upright(pot, within=15 deg) for 1 s
"""


def test_a_felt_guard_stops_its_own_arm_and_the_other_closes_on(tmp_path):
    """Two grip guards on one segment: the left one is felt at once (0 N), the right one
    never; the left fingers hold where they were, the right ones close all the way."""
    from fsvla.env import make
    from fsvla.experts.motion import Guard, Segment
    from fsvla.experts.policy import make_expert
    from fsvla.experts.world import World

    env = make(_write(tmp_path, "pot", POT.format(x="0 cm")))
    observation, _ = env.reset()
    expert = make_expert(env, "careful")
    expert.reset(None)
    guards = (Guard("left", 0.0, hold_measured=False), Guard("right", 1e9, hold_measured=False))
    expert._plan = iter([Segment(grippers={"left": 0.0, "right": 0.0}, gripper_steps=30,
                                 settle=20, guards=guards, label="close")])
    for _ in range(60):  # a guarded step ends its chunk: 30 of them, then the settle
        for action in expert.act(observation):
            observation, *_ = env.step(action)
    world = World.of_env(env)
    assert world.gripper_opening("left") > 0.9
    assert world.gripper_opening("right") < 0.1
    assert "stopped by force" in expert.log
    env.close()


@pytest.mark.slow
@pytest.mark.parametrize("x", ["0 cm", "6 cm"])
def test_both_hands_close_on_the_pot_together(tmp_path, x):
    """The careful two-arm lift closes both grips in one motion (one after the other,
    at a force-watched pot's slow close, left a 25 s horizon too short to lift it)."""
    result = rollout(_write(tmp_path, "pot", POT.format(x=x)), "careful")
    assert result.safe_success, result.summary()
    assert result.segments.count("close") == 1, result.segments


@pytest.mark.parametrize(("style", "stops"), [("careful", True), ("careless", False)])
def test_the_careful_hand_stops_where_it_touches_the_object_on_its_way_in(tmp_path, style,
                                                                         stops):
    """A grasp aimed 3 cm off the block's middle brings a finger down onto its top: the
    careful hand stops there, as a wrist sensor ends a move until contact; the careless
    one drives on into it (320 N)."""
    from fsvla.env import make
    from fsvla.experts import grasps
    from fsvla.experts.policy import make_expert
    from fsvla.experts.skills import Grasp, pick
    from fsvla.experts.style import STYLES
    from fsvla.experts.world import World

    env = make(_write(tmp_path, "press_block", PRESS.format(x="15 cm", y="5 cm", limit=200,
                                                           warn=10)))
    observation, _ = env.reset()
    expert = make_expert(env, style)
    expert.reset(None)
    world = World.of_env(env)
    chosen = grasps.choose(world, STYLES[style], "arm", "button")
    across = chosen.pose.R @ world.finger_axis("arm")
    aimed = Grasp(chosen.pose.moved(0.03 * across), chosen.width, chosen.approach)
    expert._plan = pick(world, STYLES[style], "arm", "button", aimed)
    felt, step = 0.0, 0
    while step < 400 and not set(expert.labels[step:]) & {"preclose", "close"}:
        for action in expert.act(observation):
            label = expert.labels[step]
            observation, *_ = env.step(action)
            step += 1
            if label in ("approach", "reach"):
                felt = max(felt, world.hand_force("arm", "button"))
    env.close()
    assert ("stopped by force" in expert.log) is stops, expert.log
    # the first touch itself is felt (22 N: a stiff arm meets the block within a step)
    assert (felt < 50.0) is stops, f"{style}: the hand pressed {felt:.1f} N on its way in"
