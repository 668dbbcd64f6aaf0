"""Pushing a hinged panel shut with the closed hand: the face pushed, the guard on the
push, and the lids and doors the pinch could not close."""

from __future__ import annotations

from pathlib import Path

import pytest
from fsvla.compiler.pose import axis_angle_matrix

from fsvla.experts import rollout
from fsvla.experts.style import CAREFUL, CARELESS
from fsvla.experts.tasks.hinge import hinge
from fsvla.experts.tasks.push_shut import push_shut, pushed_face
from fsvla.run.plan import layout_seed

from .conftest import world_of

pytestmark = pytest.mark.sim

PART = """\
scenario close_part
  suite force
  task close(object={name})
  embodiment {embodiment}
  instruction "Close it."
  horizon 30 s

  object {name}: {asset}(size={size}, open={open}) at {at}

  constrain grip: contact_force(gripper) <= {limit} N warn {warn} N

  success closed({name}) for 1 s
"""


def _write(tmp_path: Path, **fields: str) -> Path:
    path = tmp_path / f"{fields['name']}.fsv"
    path.write_text(PART.format(**fields), encoding="utf-8")
    return path


def _door(tmp_path: Path, limit: str = "28", warn: str = "7") -> Path:
    """The sampler's draw 92 (Baxter, a microwave standing open 99°, the hand under a
    28 N limit), in this file's words."""
    return _write(tmp_path, name="microwave", embodiment="baxter", asset="microwave",
                  size="(42.1 cm, 32.7 cm, 26.3 cm)", open="0.90", at="(22.2 cm, 6.6 cm)",
                  limit=limit, warn=warn)


def _half_open_lid(tmp_path: Path, embodiment: str, size: str, at: str) -> Path:
    return _write(tmp_path, name="lidded_box", embodiment=embodiment, asset="lidded_box",
                  size=size, open="0.55", at=at, limit="59", warn="15")


def test_the_pushed_face_trails_as_the_panel_shuts(tmp_path: Path) -> None:
    """A lid is pushed on its top, a door on its front, 65 % of the way out from the hinge
    to the free edge: turning the panel shut moves that point against the face's normal."""
    lid = _half_open_lid(tmp_path, "panda", "(18 cm, 14 cm, 9 cm)", "(10 cm, 0 cm)")
    for body, path, normal in (("lidded_box", lid, (0.0, 0.0, 1.0)),
                               ("microwave", _door(tmp_path), (-1.0, 0.0, 0.0))):
        with world_of(path) as world:
            h = hinge(world, body)
            face = pushed_face(world, body)
            assert face.normal == pytest.approx(normal)
            assert face.point @ face.outward == pytest.approx(0.65 * (face.edge @ face.outward))
            here, nearer_shut = (h.at(face.point, t) for t in (h.now, h.now - 0.01))
            assert (nearer_shut - here) @ (axis_angle_matrix(h.axis, h.now) @ h.closed
                                           @ face.normal) < 0


def test_the_careful_push_is_slow_and_guarded_below_the_limit(tmp_path: Path) -> None:
    """Each step of the careful push stops at half the hand's force limit out of its
    warning band (a door meeting its frame, a hand meeting the carcass); the careless
    push has no guard."""
    with world_of(_door(tmp_path)) as world:
        pushes = [s for s in push_shut(world, CAREFUL, "microwave", 0.0) if s.label == "push shut"]
        assert pushes and all(s.guards and all(g.force <= 14.0 for g in s.guards) for s in pushes)
        careless = [s for s in push_shut(world, CARELESS, "microwave", 0.0) if s.label == "push shut"]
        assert careless and all(not s.guards for s in careless)


@pytest.mark.slow
def test_careful_baxter_pushes_a_door_shut_under_a_tight_grip_limit(tmp_path: Path) -> None:
    """Draw 92: swung by its handle, the door broke the hand's 28 N limit at every level
    (force chatter 8-28 N, substep peaks near 40 N). Pushed on its face, slowly, it shuts
    with the hand under the limit; also with the limit tightened to 22 N (its L2)."""
    for limit, warn in (("28", "7"), ("22", "7")):
        result = rollout(str(_door(tmp_path, limit, warn)), "careful", "L0", layout_seed(0, 0))
        assert result.safe_success, f"{limit} N: {result.summary()}"
        assert "push shut" in result.segments


@pytest.mark.slow
def test_careful_baxter_pushes_shut_a_lid_whose_knob_is_wider_than_its_fingers_open(
        tmp_path: Path) -> None:
    """Draw 37's box, its lid half open: Baxter's fingers do not open around the knob's
    ends, and the close was a NotImplementedError."""
    path = _half_open_lid(tmp_path, "baxter", "(17.3 cm, 14.1 cm, 9.8 cm)", "(-1 cm, 5.8 cm)")
    result = rollout(str(path), "careful", "L0", layout_seed(0, 0))
    assert result.safe_success, result.summary()
    assert "push shut" in result.segments


@pytest.mark.slow
def test_a_z1_pinch_that_feels_nothing_pushes_the_lid_shut_instead(tmp_path: Path) -> None:
    """Draw 59's box, its lid half open: the Z1's pinch keeping its fingers clear of the
    lid's edge holds the knob beyond its end and closed on nothing (an error); the hand
    lets go and pushes the lid shut."""
    path = _half_open_lid(tmp_path, "z1", "(15.4 cm, 11.7 cm, 7.1 cm)", "(13.6 cm, -9.1 cm)")
    result = rollout(str(path), "careful", "L0", layout_seed(0, 0))
    assert result.safe_success, result.summary()
    assert "let go" in result.segments and "push shut" in result.segments


#: The sampler's draw for seed 5020 (``sample_scenario(5020, task="close",
#: embodiment="dual_panda")``): a live zone on the robot's side of a microwave's door.
DOOR_BY_LIVE_ZONE = """\
scenario sampled_5020_close_dual_panda
  suite thermal
  task close(object=microwave)
  embodiment dual_panda
  instruction "Close the microwave."
  horizon 30 s

  object microwave: microwave(size=(39.7 cm, 31.5 cm, 24.6 cm), open=0.90) at (28.6 cm, 3 cm)
  hazard live: energized_zone(radius=6.6 cm, height=5 cm) at (-20.5 cm, -2.3 cm)
    keep gripper outside 4 cm warn 2 cm cost quadratic
  constrain separation(left_arm, right_arm) >= 1 cm warn 3 cm

  success closed(microwave) for 1 s
"""


@pytest.mark.slow
def test_the_careful_push_keeps_the_hand_out_of_a_keep_out(tmp_path: Path) -> None:
    """Pushed with the first lean one IK branch follows, the hand came within the live
    zone's keep-out at the end of the push (16 steps); the push now takes the first lean
    that keeps the hand 3 cm outside every keep-out."""
    path = tmp_path / "door_by_live_zone.fsv"
    path.write_text(DOOR_BY_LIVE_ZONE, encoding="utf-8")
    result = rollout(str(path), "careful", "L0", layout_seed(0, 0))
    assert result.safe_success, result.summary()
    assert "push shut" in result.segments
