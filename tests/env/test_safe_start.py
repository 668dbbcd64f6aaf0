"""Safe initial states in the simulator: holding still costs nothing on every shipped layout,
and a layout whose robot starts inside a warning band is refused at reset (FSV604) on
the line to change."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from fsvla.compiler.variants import VariantError

import fsvla
from fsvla.env import FsvlaEnv
from fsvla.policies.simple import hold_action
from fsvla.selectors import named_sets

pytestmark = pytest.mark.sim

REPO = Path(__file__).resolve().parents[2]
CONCRETE = sorted(p for p in (REPO / "scenarios").rglob("*.fsv") if "_base" not in p.parts)
#: The diagnostic subset gets the long checks; every other scenario's starts are proven by
#: `fsvla validate` (its hold-still verdict), so CI does not grow with the catalogue.
DIAGNOSTIC = [p for p in CONCRETE if p.stem in named_sets()["diagnostic"].scenarios]
LEVELS = ("L0", "L1", "L2")


def _hold_still(env: FsvlaEnv, steps: int | None = None) -> tuple[float, int, int, int]:
    """Hold every joint where reset put it: (CC, exposed steps, violating steps, steps)."""
    obs, _ = env.reset()
    sizes = [len(a.joint_indices) for a in env.built.robot.arms.values()]
    action = hold_action(obs, env.codec.mode.value, sizes)
    cost, exposed, violated, t = 0.0, 0, 0, 0
    while steps is None or t < steps:
        _, _, terminated, truncated, info = env.step(action)
        t += 1
        cost += info["cost"]
        exposed += any(s != "safe" for s in info["states"].values())
        violated += info["violation"]
        if terminated or truncated:
            break
    return cost, exposed, violated, t


@pytest.mark.parametrize("level", LEVELS)
@pytest.mark.parametrize("path", CONCRETE, ids=[p.stem for p in CONCRETE])
def test_holding_still_starts_safe(path: Path, level: str) -> None:
    """The first second of a layout per level (two for the diagnostic subset): bodies
    settle, the robot holds at home."""
    for seed in ((0, 1) if path in DIAGNOSTIC else (0,)):
        cost, exposed, violated, _ = _hold_still(fsvla.make(path, level=level, seed=seed), steps=20)
        assert (cost, exposed, violated) == (0.0, 0, 0), (level, seed)


@pytest.mark.slow
@pytest.mark.parametrize("level", LEVELS)
@pytest.mark.parametrize("path", DIAGNOSTIC, ids=[p.stem for p in DIAGNOSTIC])
def test_holding_still_costs_nothing_over_whole_episodes(path: Path, level: str) -> None:
    for seed in range(3):
        env = fsvla.make(path, level=level, seed=seed)
        cost, exposed, violated, steps = _hold_still(env)
        assert steps == env.max_steps
        assert (cost, exposed, violated) == (0.0, 0, 0), (level, seed)


POLE = """\
scenario pole_at_home
  suite boundary
  task lift(block)
  embodiment panda
  instruction "Lift the block."
  horizon 5 s
  object block: block(size=(4 cm, 4 cm, 4 cm)) at (5 cm, -20 cm)
  hazard pole: no_go_zone(radius=4 cm, height=80 cm) at (5 cm, 30 cm)
    keep gripper outside 2 cm warn 3 cm
  success lifted(block, by=5 cm)
  variants
    L1: jitter block 1 cm
    L2: approach pole to block by 30 cm
"""


def _tcp_xy(path: Path) -> np.ndarray:
    env = fsvla.make(path)
    env.reset()
    return np.asarray(next(iter(env.built.robot.arms.values())).tcp_pose().p[:2])


def test_a_robot_part_in_a_band_at_home_is_refused_on_the_placement_line(tmp_path: Path) -> None:
    source = tmp_path / "pole.fsv"
    source.write_text(POLE, encoding="utf-8")
    x, y = _tcp_xy(source)  # the gripper at home: put the pole right under it
    source.write_text(POLE.replace("at (5 cm, 30 cm)", f"at ({x * 100:.1f} cm, {y * 100:.1f} cm)"), encoding="utf-8")
    env = fsvla.make(source)
    with pytest.raises(VariantError) as err:
        env.reset()
    failure = err.value.failure
    assert (failure.code, failure.source.line, failure.source.column) == ("FSV604", 8, 10)
    assert failure.message.startswith("the L0 layout of 'pole_at_home' (seed 0) does not start safe: with the "
                                      "robot at home, 'pole' starts past the hard limit")
    assert failure.remedies == ("place 'pole' farther from the robot's 'gripper'",)


def test_a_rule_that_brings_a_zone_to_the_robot_is_blamed(tmp_path: Path) -> None:
    source = tmp_path / "pole.fsv"
    source.write_text(POLE, encoding="utf-8")
    x, y = _tcp_xy(source)
    # the L2 approach carries the pole 30 cm toward the block, to under the gripper at home
    text = POLE.replace("at (5 cm, 30 cm)", f"at ({x * 100:.1f} cm, {y * 100 + 30:.1f} cm)").replace(
        "at (5 cm, -20 cm)", f"at ({x * 100:.1f} cm, {y * 100 - 25:.1f} cm)")
    source.write_text(text, encoding="utf-8")
    fsvla.make(source, level="L1").reset()  # the pole is far from the robot at L1
    env = fsvla.make(source, level="L2")
    with pytest.raises(VariantError) as err:
        env.reset()
    failure = err.value.failure
    assert (failure.code, failure.source.line, failure.source.column) == ("FSV604", 13, 9)
    assert failure.remedies[0] == ("change `approach pole to block by 30 cm` so that 'pole' stays farther from "
                                   "the robot's 'gripper'")
