"""What the careful expert's IK keeps an arm's links clear of: the hazards that watch them
and, where one arm of a two-arm robot works alone, the other arm (a ``separation`` limit
between the two)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from fsvla.experts import rollout
from fsvla.run.plan import layout_seed

pytestmark = pytest.mark.sim

#: Draw 11102 of the sampler, verbatim: Baxter's right arm opens a drawer in the middle of
#: the table, its hand crossing in front of the left arm at home; the arms kept 10 cm apart.
DRAWER = """\
scenario sampled_11102_open_baxter
  suite collaborative
  task open(object=drawer_cabinet)
  embodiment baxter
  instruction "Open the drawer cabinet."
  horizon 30 s

  object drawer_cabinet: drawer_cabinet(size=(39.2 cm, 34.2 cm, 22.6 cm), travel=19.6 cm) at (23.1 cm, -0.2 cm)

  constrain arms: separation(left_arm, right_arm) >= 10 cm warn 3 cm cost quadratic
  constrain separation(left_gripper, right_gripper) >= 0 warn 2 cm

  success opened(drawer_cabinet, fraction=0.6) for 0.5 s

  variants
    L1: jitter drawer_cabinet 2 cm
    L2: tighten arms to 11 cm, clutter 2 near drawer_cabinet
"""
#: Both Baxter arms lift a pot, the same separation limit on them.
POT = """\
scenario pot_lift
  suite collaborative
  task bimanual_lift(object=pot)
  embodiment baxter
  instruction "Lift the pot with both hands."
  horizon 30 s

  object pot: pot(radius=9 cm, height=8.5 cm, mass=104 g) at (-10 cm, 0 cm)

  constrain arms: separation(left_arm, right_arm) >= 10 cm warn 3 cm cost quadratic

  success lifted(pot, by=5 cm) for 0.5 s
"""
#: the runner's layout seed for its seed 0
SEED = layout_seed(0, 0)


def _write(tmp_path: Path) -> Path:
    path = tmp_path / "drawer.fsv"
    path.write_text(DRAWER, encoding="utf-8")
    return path


def test_the_working_arm_keeps_clear_of_the_other_where_it_stands(tmp_path: Path) -> None:
    """The arm that opens the drawer (the right one, nearer it) measures, at the joints
    the arms are at, the distance the monitor's own geometry gives between the two arms'
    links, less the tighter hard limit of the two separation channels; the idle arm,
    which only parks, measures nothing (no hazard watches it)."""
    from fsvla.env import make
    from fsvla.experts.policy import make_expert
    from fsvla.monitor.layout import build_layout

    env = make(str(_write(tmp_path)), "L0", SEED)
    env.reset()
    expert = make_expert(env, "careful")
    expert.reset(None)
    world = expert._world
    layout = build_layout(env.monitor.spec, env.scene_spec)
    exact = min(env.monitor.geometry.distance(layout.frames(subject), layout.frames(c.reference))
                - c.limit
                for c in world.monitor.channels if c.metric == "separation"
                for subject in c.subjects)
    working = expert._drivers["right"].clearance
    assert working is not None
    assert working(world.arm_joints("right")) == pytest.approx(exact, abs=1e-3)
    assert expert._drivers["left"].clearance is None
    env.close()


def test_a_bimanual_task_leaves_the_other_arm_to_its_plan(tmp_path: Path) -> None:
    """In a two-arm task the arms are meant to come together: neither arm's IK counts the
    other as a hazard (the plan keeps them apart itself), so with no hazard, no measure."""
    from fsvla.env import make
    from fsvla.experts.policy import make_expert

    path = tmp_path / "pot.fsv"
    path.write_text(POT, encoding="utf-8")
    env = make(str(path), "L0", SEED)
    env.reset()
    expert = make_expert(env, "careful")
    expert.reset(None)
    for driver in expert._drivers.values():
        assert driver.clearance is None
    env.close()


@pytest.mark.slow
def test_a_drawer_between_the_arms_is_opened_without_crossing_their_limit(
        tmp_path: Path) -> None:
    """Draw 11102: the right arm's straight line across in front of the left arm swung its
    elbow 8 mm into the 10 cm limit; the move goes in joint space, the arms apart."""
    result = rollout(str(_write(tmp_path)), "careful", "L0", SEED)
    assert result.success and not result.violation, result.summary()
    assert result.min_margin["arms"] >= 0.0
    assert np.isfinite(result.min_margin["arms"])
