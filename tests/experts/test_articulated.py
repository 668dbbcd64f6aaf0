"""Opening and closing articulated parts: a part that starts open (`open=`), a close of a
part already shut, and what the experts cannot do yet, said in words."""

from __future__ import annotations

from pathlib import Path

import pytest

from fsvla.experts import make_expert, rollout
from fsvla.experts.world import World

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


def test_a_part_already_shut_is_left_alone(tmp_path: Path) -> None:
    path = _write(tmp_path, DRAWER.format(embodiment="panda", open=0.0, at="(12 cm, 0.3 cm)"))
    result = rollout(str(path), "careful", "L0", 0)
    assert result.segments == ["already shut"]


def test_closing_a_standing_lid_is_a_clear_error(tmp_path: Path) -> None:
    text = DRAWER.format(embodiment="panda", open=0.9, at="(15 cm, 5 cm)").replace(
        "drawer_cabinet(size=(22 cm, 20 cm, 14 cm), travel=11 cm, open=0.9)",
        "lidded_box(size=(18 cm, 14 cm, 12 cm), open=0.9)")
    from fsvla.env import make

    env = make(str(_write(tmp_path, text)), "L0", 0)
    expert = make_expert(env, "careful")
    observation, _ = env.reset()
    expert.reset(None)
    with pytest.raises(NotImplementedError, match="cannot yet close `cabinet`'s revolute `lid`"):
        expert.act(observation)
    env.close()
