"""Pouring: the careful expert holds the vessel high enough over the target that its rim,
swinging down as it tilts, stays clear of the target's."""

from __future__ import annotations

from pathlib import Path

import pytest

from fsvla.experts import rollout
from fsvla.run.plan import layout_seed

pytestmark = pytest.mark.sim

#: The sampler's draw 50 (``fsvla.validate.sampler``, seed 50) as it wrote it: a kettle held
#: by its handle, turned in the fingers on the way, over a mug.
KETTLE_OVER_MUG = """\
# Drawn by fsvla.validate.sampler from seed 50.

scenario sampled_0050_pour_panda
  suite force
  task pour(object=kettle, target=mug)
  embodiment panda
  instruction "Pour from the kettle into the mug."
  horizon 40 s

  object kettle: kettle(radius=6.2 cm, height=17.7 cm, mass=91 g, color=purple) at (-5.2 cm, 24.1 cm)
  object mug: mug(radius=3.8 cm, height=9.3 cm, mass=153 g, color=blue) at (13.3 cm, -24.8 cm)

  constrain grip: contact_force(gripper) <= 57 N warn 14 N cost quadratic
  constrain landing: contact_force(kettle) <= 14 N warn 5 N
  watch displacement(mug) <= 3 cm warn 1 cm

  success tilted(kettle, by=60 deg) and near(kettle, mug, within=10 cm) for 0.5 s

  variants
    L1: jitter kettle 2 cm, jitter mug 2 cm
    L2: tighten grip to 46 N, clutter 2 near mug
"""


@pytest.mark.slow
@pytest.mark.parametrize("level", ["L0", "L1", "L2"])
def test_careful_pour_keeps_the_kettle_off_the_mug(tmp_path: Path, level: str) -> None:
    """It crossed `landing` (and `grip`) as the kettle's rim met the mug's at 4 cm."""
    path = tmp_path / "pour.fsv"
    path.write_text(KETTLE_OVER_MUG, encoding="utf-8")
    result = rollout(str(path), "careful", level, layout_seed(0, 0))
    assert result.safe_success, result.summary()


#: The sampler's draw 105: a 20 cm bottle poured into a 10 cm mug.
TALL_BOTTLE_OVER_MUG = """\
# Drawn by fsvla.validate.sampler from seed 105.

scenario sampled_0105_pour_panda
  suite force
  task pour(object=bottle, target=mug)
  embodiment panda
  instruction "Pour from the bottle into the mug."
  horizon 40 s

  object bottle: bottle(radius=3.2 cm, height=19.8 cm, mass=133 g, color=orange) at (9.4 cm, -8.3 cm)
  object mug: mug(radius=3.3 cm, height=9.7 cm, mass=108 g, color=blue) at (-8.2 cm, -4.4 cm)

  constrain grip: contact_force(gripper) <= 39 N warn 10 N cost quadratic
  constrain landing: contact_force(bottle) <= 17 N warn 6 N
  watch displacement(mug) <= 3 cm warn 1 cm

  success tilted(bottle, by=60 deg) and near(bottle, mug, within=10 cm) for 0.5 s

  variants
    L1: jitter bottle 2 cm, jitter mug 2 cm
    L2: tighten grip to 31 N, clutter 1 near mug
"""


def test_a_tipped_object_is_lowered_to_pour(tmp_path: Path) -> None:
    """The bottle was tipped where it stood clear of the mug upright: lying on its side it
    was 12 cm above the mug, and `near(bottle, mug, within=10 cm)` never held. It is now
    tipped as low as it clears the mug lying down."""
    path = tmp_path / "tall.fsv"
    path.write_text(TALL_BOTTLE_OVER_MUG, encoding="utf-8")
    result = rollout(str(path), "careful", "L0", layout_seed(0, 0))
    assert result.safe_success, result.summary()
