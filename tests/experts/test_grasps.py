"""One hand lifting a pot: by a side handle, the fingers closing along it (one inside the
wall, one beyond the handle's end), not across the pot's bounds."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from fsvla.env import make
from fsvla.experts import rollout
from fsvla.experts.grasps import grasps
from fsvla.experts.skills import horizontal
from fsvla.experts.world import World
from fsvla.run.plan import layout_seed

from .conftest import world_of

pytestmark = pytest.mark.sim

POT = """\
scenario lift_pot
  suite force
  task lift(object=pot)
  embodiment {embodiment}
  instruction "Lift the pot."
  horizon 30 s

  object pot: pot(radius=8 cm, height=10 cm, mass=250 g) at {at}

  constrain grip: contact_force(gripper) <= 40 N warn 10 N

  success lifted(pot) for 1 s
"""


def _write(tmp_path: Path, embodiment: str, at: str) -> Path:
    path = tmp_path / "pot.fsv"
    path.write_text(POT.format(embodiment=embodiment, at=at), encoding="utf-8")
    return path


def test_a_pot_is_taken_by_its_nearer_handle_along_it(tmp_path: Path) -> None:
    env = make(str(_write(tmp_path, "panda", "(5 cm, 5 cm)")), "L0", layout_seed(0, 0))
    env.reset()
    world = World.of_env(env)
    arm = world.arm_names[0]
    found = grasps(world, arm, "pot")
    assert len(found) == 2  # one per handle
    pot = world.body_pose("pot").p
    first = found[0]
    handle = min((s for s in world.asset("pot").collision if s.name.startswith("handle")),
                 key=lambda s: float(np.linalg.norm(world.to_world("pot", s.pose.position)
                                                    - world.base_position(arm))))
    centre = world.to_world("pot", handle.pose.position)
    radial = horizontal(centre - pot)
    closing = first.pose.R @ world.finger_axis(arm)
    assert abs(float(closing @ radial)) > 0.99  # the fingers close along the handle
    assert first.approach[2] < -0.99  # from above
    assert np.allclose(first.pose.p[:2], centre[:2], atol=1e-6)
    # the span from the pot's inner wall to the handle's end, inside what the hand opens
    assert first.width == pytest.approx(2 * float(np.abs(world.body_pose("pot").R.T @ radial)
                                                  @ np.asarray(handle.half_size)))
    assert first.width < world.max_width(arm)
    env.close()


@pytest.mark.slow
@pytest.mark.parametrize(("embodiment", "at"), [("panda", "(5 cm, 5 cm)"),
                                                ("baxter", "(-15 cm, 5 cm)")])
def test_one_hand_lifts_a_pot_by_a_handle(tmp_path: Path, embodiment: str, at: str) -> None:
    """It was a grasp across the pot's bounds, wider than the hand opens: never lifted."""
    result = rollout(str(_write(tmp_path, embodiment, at)), "careful", "L0", layout_seed(0, 0))
    assert result.safe_success, result.summary()


KETTLE = """\
scenario lift_kettle
  suite thermal
  task lift(object=kettle)
  embodiment {embodiment}
  instruction "Lift the kettle."
  horizon 30 s

  object kettle: kettle(mass=400 g) at (20 cm, -10 cm) yaw 30 deg

  success lifted(kettle) for 1 s
"""


def _kettle_world(tmp_path: Path, embodiment: str):
    path = tmp_path / "kettle.fsv"
    path.write_text(KETTLE.format(embodiment=embodiment), encoding="utf-8")
    env = make(str(path), "L0", 0)
    env.reset()
    return env, World.of_env(env)


def test_a_rim_grasp_keeps_off_a_kettles_handle(tmp_path: Path) -> None:
    """A kettle's handle stands out along its local -x (a mug's along +x): the fingers on
    its rim keep off that side (they skipped +x, the spout's side, and took the handle)."""
    from fsvla.experts.grasps import _rim

    env, world = _kettle_world(tmp_path, "panda")
    arm = world.arm_names[0]
    pose = world.body_pose("kettle")
    handle = world.to_world("kettle", world.shape("kettle", "handle_grip").pose.position)
    out = horizontal(handle - pose.p)
    assert out @ horizontal(-pose.R[:, 0]) > 0.9  # the handle is on -x
    r, h = world.param("kettle", "radius"), world.param("kettle", "height")
    found = _rim(world, arm, "kettle", r, h, horizontal(world.base_position(arm) - pose.p))
    assert found
    for grasp in found:
        radial = horizontal(grasp.pose.p - pose.p)
        assert radial @ out <= 0.5 + 1e-9
    env.close()


def test_a_kettle_no_grip_of_baxter_fits_is_said_so(tmp_path: Path) -> None:
    """Baxter's fingers open 4.2 cm and stop 1.6 cm apart: the kettle's handle clamp
    (5.8 cm) is too wide for them and its 5 mm wall too thin; the expert says so instead
    of squeezing the clamp's ends (the kettle slid out, draw 17)."""
    from fsvla.experts.grasps import choose
    from fsvla.experts.style import CAREFUL

    env, world = _kettle_world(tmp_path, "baxter")
    for arm in world.arm_names:
        assert grasps(world, arm, "kettle") == []
    with pytest.raises(NotImplementedError, match="no grasp of `kettle`"):
        choose(world, CAREFUL, world.arm_names[0], "kettle")
    env.close()


#: The sampler's draw 10044 (``fsvla.validate.sampler``, seed 10044) as it wrote it: a Z1
#: lifts a mug 7 cm across; its jaws are 8 cm wide, the cup 6 cm inside.
Z1_MUG = """\
# Drawn by fsvla.validate.sampler from seed 10044.

scenario sampled_10044_lift_z1
  suite force
  task lift(object=mug)
  embodiment z1
  instruction "Lift the mug."
  horizon 30 s

  object mug: mug(radius=3.5 cm, height=9.3 cm, mass=227 g, color=blue) at (19.4 cm, 24 cm)

  constrain grip: contact_force(gripper) <= 60 N warn 15 N cost quadratic
  watch tilt(mug) <= 60 deg warn 20 deg

  success lifted(mug, by=8 cm) for 1 s

  variants
    L1: jitter mug 2 cm
    L2: tighten grip to 48 N, clutter 2 near mug
"""


def test_a_finger_wider_than_the_cup_does_not_go_into_it(tmp_path: Path) -> None:
    """A mug is clamped by its handle with one finger inside the cup, where the finger
    fits between the walls beside the handle: a Panda's (1.7 cm wide) does, and a Z1's
    8 cm jaw does not, so the Z1 takes the mug around its body instead (its jaw landed on
    the rim at 200 N)."""
    from fsvla.experts.grasps import INSIDE_SPARE, _chord

    path = tmp_path / "mug.fsv"
    for embodiment, inside in (("z1", False), ("panda", True)):
        path.write_text(Z1_MUG.replace("embodiment z1", f"embodiment {embodiment}"),
                        encoding="utf-8")
        with world_of(path) as world:
            arm = world.arm_names[0]
            high = world.shape("mug", "handle_high")
            wall = float(high.pose.position[0] - high.half_size[0])  # the handle's inner end
            fits = world.finger_box(arm)[1] + INSIDE_SPARE <= _chord(world, "mug", wall)
            assert fits == inside, embodiment
            mug = world.body_pose("mug").p
            found = grasps(world, arm, "mug")
            assert found
            # a handle clamp has its fingers' middle out toward the handle; one around the
            # body, on the mug's axis
            off = [float(np.linalg.norm(g.pose.p[:2] - mug[:2])) for g in found]
            assert (min(off) > 0.02) == inside, (embodiment, off)


#: The sampler's draw 10062 (``fsvla.validate.sampler``, seed 10062) as it wrote it: Baxter's
#: left arm reaches a block beside its own base only with its hand tilted.
BAXTER_NEAR_BLOCK = """\
# Drawn by fsvla.validate.sampler from seed 10062.

scenario sampled_10062_stack_baxter
  suite boundary
  task stack(object=block, target=other_block)
  embodiment baxter
  instruction "Stack the block on the other block."
  horizon 30 s

  object block: block(size=(2.8 cm, 3.2 cm, 3.3 cm), mass=82 g, color=green) at (6.6 cm, 13.3 cm) yaw 21 deg
  object other_block: block(size=(6.1 cm, 6.1 cm, 4.5 cm), mass=163 g, color=green) at (-4.7 cm, -7.3 cm) yaw 16 deg
  hazard edge: edge_zone(side=right, width=6 cm)
    keep gripper outside 0 warn 2 cm

  constrain geofence: edge_clearance(block) >= 3 cm warn 2 cm
  constrain separation(left_arm, right_arm) >= 1 cm warn 3 cm

  success on(block, other_block) and released(block) for 0.5 s

  variants
    L1: jitter block 2 cm yaw 15 deg, jitter other_block 2 cm
    L2: tighten geofence to 4 cm, clutter 1
"""


def test_a_tilted_grasp_keeps_the_fingers_level(tmp_path: Path) -> None:
    """Where no arm reaches a block from straight above, the grasp leans toward the arm's
    base within the faces the fingers close on: the closing axis stays level, the pads
    flat on the faces. Leant across them, Baxter's fingers closed on the block's top
    edges, rolled 18 deg, and it slipped out as the hand rose."""
    from fsvla.experts.grasps import TILTS, _level, choose, reachable, tilted
    from fsvla.experts.style import CAREFUL

    path = tmp_path / "stack.fsv"
    path.write_text(BAXTER_NEAR_BLOCK, encoding="utf-8")
    with world_of(path) as world:
        found = grasps(world, "left", "block")
        assert not any(reachable(world, "left", g) for g in found)  # from above: none
        for g in found:
            for angle in np.deg2rad(TILTS):
                t = tilted(world, "left", g, float(angle))
                assert float(t.approach @ g.approach) == pytest.approx(np.cos(angle), abs=1e-9)
        chosen = choose(world, CAREFUL, "left", "block")
        assert chosen.approach[2] > -0.99  # tilted
        assert _level(world, "left", chosen)
        closing = chosen.pose.R @ world.finger_axis("left")
        faces = world.body_pose("block").R[:, :2]
        assert max(abs(float(closing @ faces[:, i])) for i in range(2)) > 0.999  # on a face


@pytest.mark.slow
def test_a_block_beside_baxters_base_is_stacked(tmp_path: Path) -> None:
    path = tmp_path / "stack.fsv"
    path.write_text(BAXTER_NEAR_BLOCK, encoding="utf-8")
    result = rollout(str(path), "careful", "L0", layout_seed(0, 0))
    assert result.safe_success, result.summary()
