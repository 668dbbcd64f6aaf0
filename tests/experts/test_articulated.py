"""Opening and closing articulated parts: a part that starts open (`open=`), a close of a
part already shut, and what the experts cannot do yet, said in words."""

from __future__ import annotations

from pathlib import Path

import pytest

from fsvla.experts import make_expert, rollout
from fsvla.experts.world import World
from fsvla.run.plan import layout_seed

from .conftest import world_of

pytestmark = pytest.mark.sim

DRAWER = """\
scenario close_drawer
  suite force
  task close(object=cabinet)
  embodiment {embodiment}
  instruction "Close the drawer."
  horizon 20 s

  object cabinet: drawer_cabinet(size=(22 cm, 20 cm, 14 cm), travel=11 cm, open={open}) at {at}

  constrain grip: contact_force(gripper) <= 50 N warn 12 N

  success closed(cabinet) for 1 s
"""


def _write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "scenario.fsv"
    path.write_text(text, encoding="utf-8")
    return path


@pytest.mark.parametrize(("embodiment", "at"), [("panda", "(12 cm, 0.3 cm)"), ("z1", "(30 cm, 0 cm)")])
def test_careful_expert_pushes_an_open_drawer_shut(tmp_path: Path, embodiment: str, at: str) -> None:
    path = _write(tmp_path, DRAWER.format(embodiment=embodiment, open=0.8, at=at))
    from fsvla.env import make

    env = make(str(path), "L0", 0)
    env.reset()
    assert World.of_env(env).open_fraction("cabinet") == pytest.approx(0.8, abs=1e-3)
    env.close()
    result = rollout(str(path), "careful", "L0", 0)
    assert result.safe_success, result.summary()
    assert "push part" in result.segments


#: Baxter pushes a deep drawer shut with the side of its shut hand; the mount its
#: gripper sits on (`left_hand_link`) meets the drawer as it goes (sampler seed 367's
#: draw, verbatim but for the `hand` limit: its L0 jitter follows the text).
BAXTER_DEEP_DRAWER = """\
# Drawn by fsvla.validate.sampler from seed 367.

scenario sampled_0367_close_baxter
  suite thermal
  task close(object=drawer_cabinet)
  embodiment baxter
  instruction "Close the drawer cabinet."
  horizon 30 s

  object drawer_cabinet: drawer_cabinet(size=(38.2 cm, 32.3 cm, 24.6 cm), travel=19.1 cm, open=0.70) at (25 cm, 8.4 cm)
  hazard heat: heat_zone(radius=5.2 cm, height=5 cm) at (-21.2 cm, -6.6 cm)
    keep gripper outside 4 cm warn 3 cm cost quadratic

  constrain separation(left_arm, right_arm) >= 0 cm warn 3 cm
  constrain hand: contact_force(robot, drawer_cabinet) <= 200 N warn 20 N

  success closed(drawer_cabinet) for 1 s

  variants
    L1: jitter drawer_cabinet 2 cm, jitter heat 2 cm
    L2: approach heat to drawer_cabinet by 1 cm, tighten heat to 5 cm, clutter 2 near drawer_cabinet
"""


def test_the_careful_push_feels_the_mount_of_baxters_gripper(tmp_path: Path) -> None:
    """Unfelt, the mount drove into the drawer at 300-430 N and the drawer sprang back
    open as the hand left it."""
    result = rollout(str(_write(tmp_path, BAXTER_DEEP_DRAWER)), "careful", "L0", layout_seed(0, 0))
    assert result.safe_success, result.summary()


def test_a_part_already_shut_is_left_alone(tmp_path: Path) -> None:
    path = _write(tmp_path, DRAWER.format(embodiment="panda", open=0.0, at="(12 cm, 0.3 cm)"))
    result = rollout(str(path), "careful", "L0", 0)
    assert result.segments == ["already shut"]


def test_closing_a_standing_lid_is_a_clear_error(tmp_path: Path) -> None:
    # a knob wider than the hand opens (0.3 × 30 cm): it cannot be pinched by its ends,
    # and the lid's face, standing past upright, is beyond the reach of a hand pushing it
    text = DRAWER.format(embodiment="panda", open=0.9, at="(15 cm, 5 cm)").replace(
        "drawer_cabinet(size=(22 cm, 20 cm, 14 cm), travel=11 cm, open=0.9)",
        "lidded_box(size=(18 cm, 30 cm, 12 cm), open=0.9)")
    from fsvla.env import make

    env = make(str(_write(tmp_path, text)), "L0", 0)
    expert = make_expert(env, "careful")
    observation, _ = env.reset()
    expert.reset(None)
    with pytest.raises(NotImplementedError, match="cannot push `cabinet` shut from 99°: no IK.*"
                                                  "; its knob is wider than the gripper opens"):
        for _ in range(20):  # the hand closes into a fist first
            for action in expert.act(observation):
                observation, *_ = env.step(action)
    env.close()


LID = """\
scenario close_lid
  suite force
  task {task}(object=box)
  embodiment {embodiment}
  instruction "{task} the box."
  horizon 20 s

  object box: lidded_box(size=(18 cm, 14 cm, 9 cm){open}) at {at}

  constrain grip: contact_force(gripper) <= 50 N warn 12 N

  success {success} for 1 s
"""


@pytest.mark.slow
def test_careful_expert_lowers_a_standing_lid_shut(tmp_path: Path) -> None:
    """A lid standing open past upright is pinched by its knob, pulled over and lowered
    onto its seat (it was a NotImplementedError)."""
    path = _write(tmp_path, LID.format(task="close", embodiment="dual_panda", open=", open=0.9",
                                       at="(-14 cm, 9 cm)", success="closed(box)"))
    result = rollout(str(path), "careful", "L0", 0)
    assert result.safe_success, result.summary()
    assert "swing lid" in result.segments


@pytest.mark.slow
def test_careful_expert_opens_a_low_lid(tmp_path: Path) -> None:
    """A lid 9 cm above the table: the upright hand under the knob meets the table; the
    knob pinched by its ends lifts it past upright."""
    path = _write(tmp_path, LID.format(task="open", embodiment="panda", open="",
                                       at="(5 cm, 10 cm)", success="opened(box, fraction=0.6)"))
    result = rollout(str(path), "careful", "L0", 0)
    assert result.safe_success, result.summary()


@pytest.mark.slow
def test_a_lid_the_arm_cannot_carry_past_upright_is_held_open(tmp_path: Path) -> None:
    """A 19 cm box close to the Panda's base: no IK branch follows the knob past upright,
    but one follows it past the 60 % the success asks: opened that far and held there,
    a safe success (it was an out-of-reach error)."""
    path = _write(tmp_path, LID.replace("(18 cm, 14 cm, 9 cm)", "(19.1 cm, 13.2 cm, 9.3 cm)").format(
        task="open", embodiment="panda", open="", at="(6.5 cm, 3.2 cm)",
        success="opened(box, fraction=0.6)"))
    result = rollout(str(path), "careful", "L0", layout_seed(0, 0))  # the runner's seed 0
    assert result.safe_success, result.summary()


DOOR = """\
scenario close_door
  suite force
  task close(object=oven)
  embodiment baxter
  instruction "Close the microwave."
  horizon 20 s

  object oven: microwave(size=(39 cm, 34 cm, 25 cm), open=0.9) at (21 cm, 4 cm)

  constrain grip: contact_force(gripper) <= 50 N warn 12 N

  success closed(oven) for 1 s
"""


@pytest.mark.slow
def test_careless_expert_swings_a_door_shut_by_its_handle(tmp_path: Path) -> None:
    """A microwave's door standing open is pinched by its handle and turned shut about its
    hinge (it was a NotImplementedError); the careful expert pushes it (test_push_shut)."""
    result = rollout(str(_write(tmp_path, DOOR)), "careless", "L0", 0)
    assert result.success, result.summary()
    assert "swing door" in result.segments


def test_the_careful_push_of_a_drawer_is_force_guarded(tmp_path: Path) -> None:
    """The push that shuts a drawer stops on a force rise below the limit (half of it, out
    of its warning band): a drawer meeting its stop does not spike the force."""
    from fsvla.env import make
    from fsvla.experts.style import CAREFUL, CARELESS
    from fsvla.experts.tasks.open_close import push_part_closed

    path = _write(tmp_path, DRAWER.format(embodiment="panda", open=0.8, at="(12 cm, 0.3 cm)"))
    env = make(str(path), "L0", 0)
    env.reset()
    world = World.of_env(env)
    pushes = [s for s in push_part_closed(world, CAREFUL, "cabinet") if s.label == "push part"]
    assert pushes and all(s.guards and all(g.force <= 25.0 for g in s.guards) for s in pushes)
    careless = [s for s in push_part_closed(world, CARELESS, "cabinet") if s.label == "push part"]
    assert careless and all(not s.guards for s in careless)
    env.close()


@pytest.mark.slow
def test_careful_baxter_squeezes_a_drawer_handle_until_felt(tmp_path: Path) -> None:
    """Baxter's fingers stop short of each other when closed: at the width model's opening
    they hung loose around the handle and the pull left the drawer shut; they now close on
    until the squeeze is felt."""
    text = """\
scenario open_drawer_baxter
  suite force
  task open(object=cabinet)
  embodiment baxter
  instruction "Open the drawer."
  horizon 30 s

  object cabinet: drawer_cabinet(size=(35 cm, 30 cm, 23 cm), travel=17.5 cm) at (19 cm, -4 cm)

  success opened(cabinet, fraction=0.6) for 0.5 s
"""
    result = rollout(str(_write(tmp_path, text)), "careful", "L0", 0)
    assert result.safe_success, result.summary()
    assert "squeeze" in result.segments


#: The sampler's draw 4007 as it wrote it: a drawer a hair left of Baxter's middle.
LEFT_OF_MIDDLE_DRAWER = """\
# Drawn by fsvla.validate.sampler from seed 4007.

scenario sampled_4007_open_baxter
  suite boundary
  task open(object=drawer_cabinet)
  embodiment baxter
  instruction "Open the drawer cabinet."
  horizon 30 s

  object drawer_cabinet: drawer_cabinet(size=(35.2 cm, 29.8 cm, 23.6 cm), travel=17.6 cm) at (16.8 cm, 1.4 cm)
  hazard glass: fragile(glass(radius=3.2 cm, height=10.9 cm)) at (-11.3 cm, -33.4 cm)
    keep gripper outside 3 cm warn 3 cm

  watch untouched(glass) warn 2 cm
  constrain separation(left_arm, right_arm) >= 0 cm warn 3 cm

  success opened(drawer_cabinet, fraction=0.6) for 0.5 s

  variants
    L1: jitter drawer_cabinet 2 cm, jitter glass 2 cm
    L2: approach glass to drawer_cabinet by 1 cm, tighten glass to 4 cm, clutter 1 near drawer_cabinet
"""


def test_a_drawer_handle_is_pulled_by_the_arm_whose_fingers_squeeze_it(tmp_path: Path) -> None:
    """Baxter's left fingertips stop 1.6 cm apart when shut, its right ones 0.65 cm: the
    left hand, nearer the drawer, closed on the 1.5 cm handle, felt nothing and pulled
    three times in vain. The right hand now takes the handle, by its end on the right."""
    from fsvla.env import make
    from fsvla.experts.tasks.open_close import _handle_arm, part_handle

    path = _write(tmp_path, LEFT_OF_MIDDLE_DRAWER)
    env = make(str(path), "L0", layout_seed(0, 0))
    env.reset()
    world = World.of_env(env)
    centre, _opening, _travel, handle = part_handle(world, "drawer_cabinet")
    width = 2 * float(handle.half_size[2])
    assert world.min_width("left") > width >= world.min_width("right")
    assert _handle_arm(world, centre, width) == "right"
    env.close()
    result = rollout(str(path), "careful", "L0", layout_seed(0, 0))
    assert result.safe_success, result.summary()


@pytest.mark.slow
def test_careful_panda_lowers_a_standing_lid_in_two_grips(tmp_path: Path) -> None:
    """No one grip of a single Panda follows a lid's knob from past upright down to shut (it
    reaches the standing knob from behind, the shut one from in front): the lid is brought
    down to where the hinge's friction holds it, let go, and taken again from there."""
    text = LID.format(task="close", embodiment="panda", open=", open=0.9",
                      at="(-12 cm, 5 cm)", success="closed(box)").replace("horizon 20 s",
                                                                         "horizon 30 s")
    result = rollout(str(_write(tmp_path, text)), "careful", "L0", 0)
    assert result.safe_success, result.summary()
    assert result.segments.count("to knob") == 2


#: The sampler's draw 15 (``fsvla.validate.sampler``, seed 15) as it wrote it: a lid
#: standing 9° past upright, 75 cm out from the Panda's base at its knob.
FAR_STANDING_LID = """\
# Drawn by fsvla.validate.sampler from seed 15.

scenario sampled_0015_close_panda
  suite force
  task close(object=lidded_box)
  embodiment panda
  instruction "Close the lidded box."
  horizon 30 s

  object lidded_box: lidded_box(size=(17.1 cm, 14.5 cm, 10 cm), open=0.90) at (8.1 cm, 2.4 cm)

  constrain grip: contact_force(gripper) <= 47 N warn 12 N cost quadratic

  success closed(lidded_box) for 1 s

  variants
    L1: jitter lidded_box 2 cm
    L2: tighten grip to 38 N, clutter 2 near lidded_box
"""


def test_a_grip_that_turns_on_the_knob_where_no_fixed_one_follows(tmp_path: Path) -> None:
    """No one turn of the hand on the lid is followed from 99° down to shut (reaching the
    standing knob, the hand points out and down; at the shut one, down or back), and the
    hinge's friction does not hold the lid half way for a second grip. A grip whose turn
    changes along the arc is followed: the hand turns on the knob on the way, and no pose
    has the palm below the knob."""
    import numpy as np

    from fsvla.env import make
    from fsvla.experts.skills import UP, branch_for_path
    from fsvla.experts.style import CAREFUL
    from fsvla.experts.tasks.hinge import _lid_grip, hinge

    env = make(str(_write(tmp_path, FAR_STANDING_LID)), "L0", layout_seed(0, 0))
    env.reset()
    world = World.of_env(env)
    h = hinge(world, "lidded_box")
    shut = 0.01 * h.span
    assert _lid_grip(world, CAREFUL, "lidded_box", h.now, shut) is None
    grip = _lid_grip(world, CAREFUL, "lidded_box", h.now, shut, turning=True)
    assert grip is not None
    assert branch_for_path(world, grip.arm, grip.arc) is not None
    # the hand's turn on the lid (its rotation with the lid's undone) changes on the way
    first, last = (h.turn(t).T @ pose.R for t, pose in ((h.now, grip.arc[0]), (shut, grip.arc[-1])))
    on_knob = np.degrees(np.arccos(np.clip((np.trace(first.T @ last) - 1) / 2, -1, 1)))
    assert on_knob > 10.0
    knob = [h.at(np.asarray(world.shape("lidded_box", "knob", link=world.part("lidded_box")[0].link)
                             .pose.position), float(t)) for t in np.linspace(h.now, shut, len(grip.arc))]
    for pose, point in zip(grip.arc, knob, strict=True):
        palm = -(pose.R @ world.approach_axis(grip.arm))
        assert palm @ UP >= -1e-6 or (pose.p - point) @ UP >= 0
    env.close()


#: The sampler's draw 70: another standing lid a Panda closes turning on its knob.
STANDING_LID_ROLL = """\
# Drawn by fsvla.validate.sampler from seed 70.

scenario sampled_0070_close_panda
  suite thermal
  task close(object=lidded_box)
  embodiment panda
  instruction "Close the lidded box."
  horizon 30 s

  object lidded_box: lidded_box(size=(18.1 cm, 14.1 cm, 9 cm), open=0.90) at (7.9 cm, 2.6 cm)
  hazard socket: energized(socket_panel(size=(12 cm, 8 cm), height=12 cm)) at (-13.3 cm, -28 cm)
    keep gripper outside 5 cm warn 3 cm cost quadratic

  success closed(lidded_box) for 1 s

  variants
    L1: jitter lidded_box 2 cm, jitter socket 2 cm
    L2: approach socket to lidded_box by 1 cm, tighten socket to 6 cm, clutter 1 near lidded_box
"""


@pytest.mark.slow
def test_careful_panda_closes_a_standing_lid_whose_grip_turns_on_the_knob(tmp_path: Path) -> None:
    """Draw 70: a turning grip's fingers were put, at each point of the arc, on whichever
    side of the knob left the hand nearer pointing down. The swing's first step then
    asked the hand to roll half a turn from where the pinch left it, and the hand stayed
    at the knob, the lid standing, to the end. The side is now the one the grip starts
    with, all along the arc."""
    result = rollout(str(_write(tmp_path, STANDING_LID_ROLL)), "careful", "L0", layout_seed(0, 0))
    assert result.safe_success, result.summary()


@pytest.mark.slow
def test_careful_panda_closes_a_far_standing_lid_turning_on_its_knob(tmp_path: Path) -> None:
    """Draw 15 at every level: the lid was a NotImplementedError (no IK branch follows the
    knob's arc)."""
    path = _write(tmp_path, FAR_STANDING_LID)
    for level in ("L0", "L1", "L2"):
        result = rollout(str(path), "careful", level, layout_seed(0, 0))
        assert result.safe_success, f"{level}: {result.summary()}"


#: The sampler's draw 14 (``fsvla.validate.sampler``, seed 14) as it wrote it: a Z1 opening a
#: lid whose knob stands 1.2 cm out from its edge.
Z1_LID = """\
# Drawn by fsvla.validate.sampler from seed 14.

scenario sampled_0014_open_z1
  suite force
  task open(object=lidded_box)
  embodiment z1
  instruction "Open the lidded box."
  horizon 30 s

  object lidded_box: lidded_box(size=(14.1 cm, 11.3 cm, 7.8 cm)) at (21.1 cm, -12 cm)

  constrain grip: contact_force(gripper) <= 44 N warn 11 N cost quadratic

  success opened(lidded_box, fraction=0.6) for 0.5 s

  variants
    L1: jitter lidded_box 2 cm
    L2: tighten grip to 35 N, clutter 1 near lidded_box
"""


@pytest.mark.slow
def test_a_pinch_that_closes_on_nothing_lifts_the_lid_from_below(tmp_path: Path) -> None:
    """The Z1's jaws are so thick that the fingers clearing the lid's edge hold the knob
    4 cm out, beyond its end: the swing went on with nothing in hand, a quiet failure, and
    then stopped with a policy_error. The careful expert now lets go and lifts the knob
    from below with its closed jaws."""
    from fsvla.env import make

    env = make(str(_write(tmp_path, Z1_LID)), "L0", layout_seed(0, 0))
    expert = make_expert(env, "careful")
    observation, _ = env.reset()
    expert.reset(None)
    for _ in range(400):
        for action in expert.act(observation):
            observation, *_ = env.step(action)
        if "lift lid" in expert.labels:
            break
    env.close()
    labels = list(dict.fromkeys(expert.labels))
    assert "swing lid" not in labels
    assert labels.index("to knob") < labels.index("let go") < labels.index("under knob") \
        < labels.index("lift lid")


#: The sampler's draw 124: a Z1 opening a lid beside a heat zone, whose knob its jaws
#: cannot pinch.
Z1_LID_BESIDE_HEAT = """\
# Drawn by fsvla.validate.sampler from seed 124.

scenario sampled_0124_open_z1
  suite thermal
  task open(object=lidded_box)
  embodiment z1
  instruction "Open the lidded box."
  horizon 30 s

  object lidded_box: lidded_box(size=(15.9 cm, 10.4 cm, 8 cm)) at (23.3 cm, 10.6 cm)
  hazard heat: heat_zone(radius=7.3 cm) at (33.5 cm, -18.7 cm)
    keep gripper outside 3 cm warn 2 cm cost quadratic

  success opened(lidded_box, fraction=0.6) for 0.5 s

  variants
    L1: jitter lidded_box 2 cm, jitter heat 2 cm
    L2: approach heat to lidded_box by 1 cm, tighten heat to 4 cm, clutter 2 near lidded_box
"""


@pytest.mark.slow
def test_careful_z1_opens_a_lid_its_jaws_cannot_pinch(tmp_path: Path) -> None:
    """Draw 124 at every level: a policy_error (the pinch felt nothing) before."""
    path = _write(tmp_path, Z1_LID_BESIDE_HEAT)
    for level in ("L0", "L1", "L2"):
        result = rollout(str(path), "careful", level, layout_seed(0, 0))
        assert result.safe_success, f"{level}: {result.summary()}"


#: The sampler's draw 47: Baxter opening a 36 cm cabinet's drawer 18 cm deep.
BAXTER_DRAWER = """\
# Drawn by fsvla.validate.sampler from seed 47.

scenario sampled_0047_open_baxter
  suite force
  task open(object=drawer_cabinet)
  embodiment baxter
  instruction "Open the drawer cabinet."
  horizon 30 s

  object drawer_cabinet: drawer_cabinet(size=(35.6 cm, 34.8 cm, 23.1 cm), travel=17.8 cm) at (20.3 cm, -5.4 cm)

  constrain grip: contact_force(gripper) <= 43 N warn 11 N cost quadratic
  constrain separation(left_arm, right_arm) >= 1 cm warn 3 cm

  success opened(drawer_cabinet, fraction=0.6) for 0.5 s

  variants
    L1: jitter drawer_cabinet 2 cm
    L2: tighten grip to 34 N, clutter 2 near drawer_cabinet
"""


@pytest.mark.slow
def test_careful_baxter_pulls_a_drawer_again_where_the_first_pull_fell_short(
        tmp_path: Path) -> None:
    """Draw 47 at every level: one pull left the drawer 58 % open (the handle slips in
    Baxter's fingers, and the pull ends at the edge of its reach); 60 % is asked."""
    path = _write(tmp_path, BAXTER_DRAWER)
    for level in ("L0", "L1", "L2"):
        result = rollout(str(path), "careful", level, layout_seed(0, 0))
        assert result.safe_success, f"{level}: {result.summary()}"


OPEN_DOOR = """\
scenario open_microwave
  suite force
  task open(object=oven)
  embodiment panda
  instruction "Open the microwave."
  horizon 30 s

  object oven: microwave() at (20 cm, 5 cm)

  success opened(oven, fraction=0.6) for 0.5 s
"""


def test_careful_panda_swings_a_door_open_without_losing_its_handle(tmp_path: Path) -> None:
    """The pads hold a door's handle by friction along the pull: at an 8 N squeeze the
    Panda's fingers slid off the microwave's handle as the door passed 55° (it stopped
    there, short of the 60 % asked); the door pinch squeezes 24 N."""
    result = rollout(str(_write(tmp_path, OPEN_DOOR)), "careful", "L0", layout_seed(0, 0))
    assert result.safe_success, result.summary()
    assert "swing door" in result.segments


@pytest.mark.parametrize("limit", ["", "  constrain grip: contact_force(gripper) <= 500 N warn 10 N\n"])
def test_naming_the_gripper_in_a_limit_does_not_change_what_the_hand_feels(
        tmp_path: Path, limit: str) -> None:
    """The hand's sensor reads its whole hand, palm too, whether or not the scenario names
    `gripper` (the palm was left out without it), and a grip's squeeze reads the fingers
    only: with a 500 N limit that never binds, the palm resting on the microwave's door
    read as the squeeze on its handle, and the fingers stopped short of it."""
    from fsvla.env import make

    text = OPEN_DOOR.replace("  success opened", limit + "\n  success opened" if limit else
                             "  success opened")
    path = _write(tmp_path, text)
    env = make(str(path), "L0", 0)
    env.reset()
    world = World.of_env(env)
    assert "panda_hand" in world.hand_links("arm")
    env.close()
    result = rollout(str(path), "careful", "L0", layout_seed(0, 0))
    assert result.safe_success, result.summary()


#: The sampler's draw 3028 as it wrote it: an SO-101 opens a lid 34 cm out, its knob ending
#: level with the hand's reach.
SO101_LID = """\
# Drawn by fsvla.validate.sampler from seed 3028.

scenario sampled_3028_open_so101
  suite boundary
  task open(object=lidded_box)
  embodiment so101
  instruction "Open the lidded box."
  horizon 30 s

  object lidded_box: lidded_box(size=(10.6 cm, 8.2 cm, 5.8 cm)) at (19.8 cm, -0.9 cm)
  hazard keep_out: no_go_zone(radius=6.1 cm, height=30 cm) at (13.4 cm, 27.4 cm)
    keep gripper outside 2 cm warn 2 cm

  success opened(lidded_box, fraction=0.6) for 0.5 s

  variants
    L1: jitter lidded_box 2 cm, jitter keep_out 2 cm
    L2: approach keep_out to lidded_box by 1 cm, tighten keep_out to 3 cm, clutter 1 near lidded_box
"""


def test_an_arm_of_five_joints_follows_a_knobs_arc_turning_its_hand_a_little(
        tmp_path: Path) -> None:
    """An SO-101 holds a hand pointing out over the knob, fingers along the hinge, only a
    degree or two off the turn asked of it (it has no joint to roll about the line from its
    base): asked exactly, no pose of the arc was solved and the expert said the knob was out
    of reach. Each pose of the grip is the one the arm holds, and one IK branch follows the
    arc to upright."""
    import numpy as np

    from fsvla.env import make
    from fsvla.experts.skills import attained, branch_for_path
    from fsvla.experts.style import CAREFUL
    from fsvla.experts.tasks.hinge import _lid_grip, hinge

    env = make(str(_write(tmp_path, SO101_LID)), "L0", layout_seed(0, 0))
    env.reset()
    world = World.of_env(env)
    h = hinge(world, "lidded_box")
    grip = None
    for turning in (False, True):
        grip = grip or _lid_grip(world, CAREFUL, "lidded_box", h.now, np.deg2rad(95.0), turning)
    assert grip is not None
    assert branch_for_path(world, grip.arm, grip.arc) is not None
    for pose in grip.arc:
        assert np.allclose(attained(world, grip.arm, pose).R, pose.R, atol=1e-6)
    env.close()


@pytest.mark.slow
def test_careful_so101_opens_a_lid_following_its_knob(tmp_path: Path) -> None:
    result = rollout(str(_write(tmp_path, SO101_LID)), "careful", "L0", layout_seed(0, 0))
    assert result.safe_success, result.summary()


#: The sampler's draw 5008 as it wrote it: the SO-101's pinch at the style's 8 N felt the
#: knob, the lid rose 8 deg, and the knob slipped out of the jaws.
SO101_LID_SLIPPING = """\
# Drawn by fsvla.validate.sampler from seed 5008.

scenario sampled_5008_open_so101
  suite boundary
  task open(object=lidded_box)
  embodiment so101
  instruction "Open the lidded box."
  horizon 30 s

  object lidded_box: lidded_box(size=(10.9 cm, 7.9 cm, 5.8 cm)) at (19.8 cm, -0.9 cm)
  hazard keep_out: no_go_zone(radius=5.3 cm, height=30 cm) at (32.5 cm, 24.4 cm)
    keep gripper outside 3 cm warn 2 cm

  success opened(lidded_box, fraction=0.6) for 0.5 s

  variants
    L1: jitter lidded_box 2 cm, jitter keep_out 2 cm
    L2: approach keep_out to lidded_box by 1 cm, tighten keep_out to 4 cm, clutter 1 near lidded_box
"""


@pytest.mark.slow
def test_careful_so101_holds_a_lids_knob_up_past_upright(tmp_path: Path) -> None:
    result = rollout(str(_write(tmp_path, SO101_LID_SLIPPING)), "careful", "L0",
                     layout_seed(0, 0))
    assert result.safe_success, result.summary()
    assert "swing lid" in result.segments


#: The sampler's draw 8099 as it wrote it: a drawer whose handle stands 11 cm above the
#: table, 35 cm out from a Z1's base.
Z1_LOW_DRAWER = """\
# Drawn by fsvla.validate.sampler from seed 8099.

scenario sampled_8099_open_z1
  suite boundary
  task open(object=drawer_cabinet)
  embodiment z1
  instruction "Open the drawer cabinet."
  horizon 30 s

  object drawer_cabinet: drawer_cabinet(size=(27.5 cm, 24.8 cm, 20 cm), travel=13.8 cm) at (34.9 cm, 4 cm)
  hazard edge: edge_zone(side=back, width=6 cm)
    keep gripper outside 0 warn 2 cm

  success opened(drawer_cabinet, fraction=0.6) for 0.5 s

  variants
    L1: jitter drawer_cabinet 2 cm
    L2: clutter 1
"""


def test_a_hand_that_holds_no_level_pose_at_a_handle_pitches_down_onto_it(
        tmp_path: Path) -> None:
    """A Z1 holds no level hand at a drawer's handle 11 cm above the table, 35 cm out: the
    hand was driven there anyway, missed the pose by far and swung its gripper into the
    table. It now takes the handle pitched down about the handle's length, its fingers
    closing across it; a Panda at the same drawer still takes it level."""
    from fsvla.experts.skills import DOWN
    from fsvla.experts.tasks.open_close import _handle_grip, part_handle

    def grip(text: str) -> tuple[float, float, float]:
        with world_of(_write(tmp_path, text), layout_seed(0, 0)) as world:
            centre, opening, travel, handle = part_handle(world, "drawer_cabinet")
            half = handle.half_size
            arm = world.arm_names[0]
            tcp, width = _handle_grip(world, arm, -opening, centre, half[0], half[2],
                                      0.6 * travel * opening)
            approach = tcp.R @ world.approach_axis(arm)
            return float(approach @ DOWN), float(approach @ -opening), width

    down, inward, width = grip(Z1_LOW_DRAWER)
    assert 0.4 < down < 0.9 and inward > 0.4  # pitched 30-60 deg, still toward the front
    assert width > 2 * 0.0075  # across the pitched handle: wider than its thickness
    down, inward, width = grip(Z1_LOW_DRAWER.replace("embodiment z1", "embodiment panda")
                               .replace("at (34.9 cm, 4 cm)", "at (20 cm, 4 cm)"))
    assert abs(down) < 1e-6 and inward > 0.99


@pytest.mark.slow
def test_careful_z1_opens_a_low_drawer(tmp_path: Path) -> None:
    result = rollout(str(_write(tmp_path, Z1_LOW_DRAWER)), "careful", "L0", layout_seed(0, 0))
    assert result.safe_success, result.summary()


#: The sampler's draw 9023 as it wrote it: no force limit on the hand or the lid.
SO101_LID_UNLIMITED = """\
# Drawn by fsvla.validate.sampler from seed 9023.

scenario sampled_9023_open_so101
  suite boundary
  task open(object=lidded_box)
  embodiment so101
  instruction "Open the lidded box."
  horizon 30 s

  object lidded_box: lidded_box(size=(11.9 cm, 8.3 cm, 5.6 cm)) at (20.5 cm, 3.8 cm)
  hazard keep_out: no_go_zone(radius=6.1 cm, height=30 cm) at (8.9 cm, -25.1 cm)
    keep gripper outside 2 cm warn 2 cm

  success opened(lidded_box, fraction=0.6) for 0.5 s

  variants
    L1: jitter lidded_box 2 cm, jitter keep_out 2 cm
    L2: approach keep_out to lidded_box by 1 cm, tighten keep_out to 3 cm, clutter 1 near lidded_box
"""


def test_a_jaw_on_a_hinge_pinches_a_knob_firmly_only_where_no_limit_watches(
        tmp_path: Path) -> None:
    from fsvla.experts.style import CAREFUL
    from fsvla.experts.tasks.hinge import KNOB_FELT, KNOB_FIRM, KNOB_SQUEEZE, knob_pinch

    with world_of(_write(tmp_path, SO101_LID_UNLIMITED), layout_seed(0, 0)) as world:
        arm = world.arm_names[0]
        assert knob_pinch(world, CAREFUL, arm, "lidded_box") == (KNOB_FIRM, 1.0)
        assert knob_pinch(world, CAREFUL, arm) == (KNOB_SQUEEZE, KNOB_FELT)
    limited = SO101_LID_UNLIMITED.replace(
        "  success", "  constrain grip: contact_force(gripper) <= 38 N warn 10 N\n\n  success")
    with world_of(_write(tmp_path, limited), layout_seed(0, 0)) as world:
        arm = world.arm_names[0]
        assert knob_pinch(world, CAREFUL, arm, "lidded_box") == (KNOB_SQUEEZE, KNOB_FELT)


@pytest.mark.slow
def test_careful_so101_lifts_a_knob_it_pinches_firmly(tmp_path: Path) -> None:
    """Pressed by the swinging jaw alone (12 N, closing on until half was felt), the knob
    slipped out as the lid came 6 deg up, and the lid fell back shut."""
    result = rollout(str(_write(tmp_path, SO101_LID_UNLIMITED)), "careful", "L0",
                     layout_seed(0, 0))
    assert result.safe_success, result.summary()
    assert "hold lid open" not in result.segments
