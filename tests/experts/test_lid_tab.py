"""Pulling a lid that stands past upright back over it by its knob held flat
(``fsvla.experts.tasks.lid_tab``)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from fsvla.env import make
from fsvla.experts import rollout
from fsvla.experts.style import CAREFUL
from fsvla.experts.tasks.hinge import hinge
from fsvla.experts.tasks.lid_tab import tab_grip
from fsvla.experts.world import World
from fsvla.run.plan import layout_seed


def _write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "scenario.fsv"
    path.write_text(text, encoding="utf-8")
    return path


#: The sampler's draw 3040 as it wrote it: a lid standing 9° past upright whose knob no
#: Panda grip by its ends carries down (a `policy_error` before the knob was held flat).
PANDA_STANDING_LID = """\
# Drawn by fsvla.validate.sampler from seed 3040.

scenario sampled_3040_close_panda
  suite force
  task close(object=lidded_box)
  embodiment panda
  instruction "Close the lidded box."
  horizon 30 s

  object lidded_box: lidded_box(size=(19.5 cm, 13.2 cm, 8.7 cm), open=0.90) at (5.9 cm, -12.4 cm)

  constrain grip: contact_force(gripper) <= 55 N warn 14 N cost quadratic

  success closed(lidded_box) for 1 s

  variants
    L1: jitter lidded_box 2 cm
    L2: tighten grip to 44 N, clutter 2 near lidded_box
"""

#: The sampler's draw 7022: Baxter's fingers stop 6.5 mm (right) and 16 mm (left) apart
#: when shut, wider than a lid 9.5 mm thick less the squeeze they need.
BAXTER_STANDING_LID = """\
scenario baxter_standing_lid
  suite collaborative
  task close(object=lidded_box)
  embodiment baxter
  instruction "Close the lidded box."
  horizon 30 s

  object lidded_box: lidded_box(size=(17.3 cm, 14.5 cm, 9.5 cm), open=0.90) at (12 cm, 1 cm)

  success closed(lidded_box) for 1 s
"""


def _world(tmp_path: Path, text: str):
    env = make(str(_write(tmp_path, text)), "L0", layout_seed(0, 0))
    env.reset()
    return env, World.of_env(env)


def test_the_flat_hold_turns_the_hand_with_the_lid(tmp_path: Path) -> None:
    env, world = _world(tmp_path, PANDA_STANDING_LID)
    h = hinge(world, "lidded_box")
    end = np.deg2rad(60.0)
    grip = tab_grip(world, CAREFUL, "lidded_box", end)
    assert grip is not None
    assert grip.width == pytest.approx(0.0087, abs=1e-4)  # the lid's thickness
    first, last = grip.arc[0], grip.arc[-1]
    # the hand turns with the lid: its turn on the lid is the same at both ends
    on_lid = [h.turn(t).T @ pose.R for t, pose in ((h.now, first), (end, last))]
    assert np.allclose(on_lid[0], on_lid[1], atol=0.05)
    # it comes down onto the tab along the lid, from beyond its tip
    assert grip.back.p[2] > first.p[2] + 0.05
    env.close()


def test_fingers_that_stop_apart_wider_than_the_lid_hold_no_tab(tmp_path: Path) -> None:
    env, world = _world(tmp_path, BAXTER_STANDING_LID)
    assert tab_grip(world, CAREFUL, "lidded_box", np.deg2rad(60.0)) is None
    env.close()


@pytest.mark.slow
def test_careful_panda_pulls_a_standing_lid_back_over_upright(tmp_path: Path) -> None:
    result = rollout(str(_write(tmp_path, PANDA_STANDING_LID)), "careful", "L0",
                     layout_seed(0, 0))
    assert result.safe_success, result.summary()
    assert "pull lid over" in result.segments
