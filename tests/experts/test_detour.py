"""A push's route over the table around the keep-outs (``fsvla.experts.tasks.detour``)."""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fsvla.env import make
from fsvla.experts import rollout
from fsvla.experts.tasks.detour import _around, _clear, _shortest, detour
from fsvla.experts.world import World, box_distance
from fsvla.run.plan import layout_seed


def _write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "scenario.fsv"
    path.write_text(text, encoding="utf-8")
    return path


#: The sampler's draw 7020 as it wrote it: the straight line from the block to the other
#: block passes 3 cm from the heat zone's keep-out (a careful unsafe success before).
HEAT_ACROSS_THE_PUSH = """\
# Drawn by fsvla.validate.sampler from seed 7020.

scenario sampled_7020_push_panda
  suite thermal
  task push(object=block, target=other_block)
  embodiment panda
  instruction "Push the block to the block."
  horizon 30 s

  object block: block(size=(3.3 cm, 3.4 cm, 4.2 cm), mass=124 g, color=red) at (-0.6 cm, 18.3 cm) yaw -22 deg
  object other_block: block(size=(3 cm, 3 cm, 1 cm), mass=117 g, color=red) at (4 cm, -25.6 cm) yaw -10 deg
  hazard heat: heat_zone(radius=7.5 cm) at (-10.2 cm, -3.9 cm)
    keep gripper, block outside 4 cm warn 3 cm cost quadratic

  success near(block, other_block, within=3 cm)

  variants
    L1: jitter block 2 cm yaw 15 deg, jitter other_block 2 cm, jitter heat 2 cm
    L2: approach heat to block by 1 cm, tighten heat to 5 cm, clutter 1 near other_block
"""


def test_the_route_goes_round_the_heat_zone_clear_of_its_keep_out(tmp_path: Path) -> None:
    env = make(str(_write(tmp_path, HEAT_ACROSS_THE_PUSH)), "L0", layout_seed(0, 0))
    env.reset()
    world = World.of_env(env)
    via = detour(world, "arm", "block", "other_block").points
    assert via, "the straight line crosses the keep-out: a detour is needed"
    heat = next(o for o in world.obstacles() if o.name == "heat")
    route = [world.body_pose("block").p[:2], *(p[:2] for p in via),
             world.body_pose("other_block").p[:2]]
    for a, b in itertools.pairwise(route):
        for s in np.linspace(0.0, 1.0, 50):
            point = a + s * (b - a)
            # the block (1.7 cm half-width) keeps the 7 cm keep-out, with the hand's room
            assert box_distance(point, heat.lo[:2], heat.hi[:2]) > heat.margin + 0.017
    # round the side away from the zone (+x), not through it
    assert all(p[0] > heat.hi[0] for p in via)
    env.close()


def test_a_clear_line_needs_no_detour(tmp_path: Path) -> None:
    text = HEAT_ACROSS_THE_PUSH.replace("at (-10.2 cm, -3.9 cm)", "at (-30 cm, -3.9 cm)")
    env = make(str(_write(tmp_path, text)), "L0", layout_seed(0, 0))
    env.reset()
    assert detour(World.of_env(env), "arm", "block", "other_block").points == []
    env.close()


@pytest.mark.slow
def test_careful_push_goes_round_a_heat_zone(tmp_path: Path) -> None:
    result = rollout(str(_write(tmp_path, HEAT_ACROSS_THE_PUSH)), "careful", "L0",
                     layout_seed(0, 0))
    assert result.safe_success, result.summary()
    assert result.min_margin["heat"] > 0.0


_coord = st.floats(-0.4, 0.4)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(_coord, _coord, st.floats(0.02, 0.15), st.floats(0.02, 0.15),
                          st.floats(0.03, 0.15)), min_size=1, max_size=3),
       _coord, _coord, _coord, _coord)
def test_a_found_route_keeps_every_box_clear(boxes, ax, ay, bx, by) -> None:
    grown = [(np.array([x, y]), np.array([x + w, y + h]), keep) for x, y, w, h, keep in boxes]
    a, b = np.array([ax, ay]), np.array([bx, by])
    if any(box_distance(p, lo, hi) < keep for p in (a, b) for lo, hi, keep in grown):
        return  # the sampler's ends stand clear; these do not
    nodes = [a, b] + [p for box in grown for p in _around(*box)
                      if all(box_distance(p, lo, hi) >= keep for lo, hi, keep in grown)]
    path = _shortest(nodes, grown)
    if _clear(a, b, grown):
        assert path == [0, 1]
    if path is None:
        return
    assert path[0] == 0 and path[-1] == 1
    for i, j in itertools.pairwise(path):
        for s in np.linspace(0.0, 1.0, 40):
            point = nodes[i] + s * (nodes[j] - nodes[i])
            assert all(box_distance(point, lo, hi) > keep - 2e-3 for lo, hi, keep in grown)
