"""Every catalog predicate on hand-made states."""

from __future__ import annotations

import math
from pathlib import Path

from fsvla.compiler.monitor import lower_monitor
from fsvla.compiler.scene import lower_scene
from fsvla.dsl.catalog import PREDICATES
from fsvla.dsl.loader import ScenarioLoader
from fsvla.dsl.models import AllOf, AnyOf, Not, Predicate

from fsvla.monitor.layout import build_geometry, build_layout
from fsvla.monitor.predicates import EVALUATORS, Scope, holds

from .conftest import HAND, LEFT, RIGHT, rotation_x, state, translation

REPO = Path(__file__).resolve().parents[2]


def P(name: str, *args: str, **params) -> Predicate:
    return Predicate(name=name, args=args, params=params)


def _scope(world, poses=None, **kw) -> Scope:
    evaluator, base = world
    evaluator.reset(state(base))
    s = state(poses if poses is not None else base, 1, **kw)
    evaluator.geometry.set_poses(s.poses)
    return Scope(s, evaluator.layout, evaluator.geometry)


def test_every_catalog_predicate_has_an_evaluator():
    assert set(EVALUATORS) == set(PREDICATES)


def test_grasped_released_and_pressed(world):
    fingers = {(LEFT, "pot"): [0, 4.0, 0], (RIGHT, "pot"): [0, -4.0, 0]}
    one = {(LEFT, "pot"): [0, 4.0, 0]}
    assert holds(P("grasped", "pot"), _scope(world, last_contacts=fingers))
    assert holds(P("grasped", "pot", "arm"), _scope(world, last_contacts=fingers))
    assert not holds(P("grasped", "pot"), _scope(world, last_contacts=one))
    assert not holds(P("released", "pot"), _scope(world, last_contacts=one))
    assert holds(P("released", "pot"), _scope(world))
    assert holds(P("pressed", "pot"), _scope(world, last_contacts={("pot", HAND): [0, 0, -2.0]}))
    assert not holds(P("pressed", "pot"), _scope(world, last_contacts={("pot", HAND): [0, 0, 2.0]}))


def test_lifted_on_and_inside(world):
    base = world[1]
    up = dict(base, pot=base["pot"] @ translation(0, 0, 0.04))
    assert holds(P("lifted", "pot", by=0.03), _scope(world, up))
    assert not holds(P("lifted", "pot", by=0.05), _scope(world, up))
    assert holds(P("on", "pot", "table"), _scope(world))
    assert not holds(P("on", "pot", "table"), _scope(world, up))
    assert not holds(P("on", "glass", "board"), _scope(world))
    in_pot = dict(base, glass=base["pot"] @ translation(0, 0, 0.01))
    assert holds(P("inside", "glass", "pot"), _scope(world, in_pot))
    assert not holds(P("inside", "glass", "pot"), _scope(world))


def test_upright_tilted_aligned_near_touching(world):
    base = world[1]
    tipped = dict(base, glass=rotation_x(math.radians(50), base["glass"]))
    assert holds(P("upright", "glass"), _scope(world))
    assert not holds(P("upright", "glass", within=math.radians(15)), _scope(world, tipped))
    assert holds(P("tilted", "glass", by=math.radians(45)), _scope(world, tipped))
    # the gripper's reference point is the TCP frame, at (0, 0.3, 0.35) in the fixture
    near_pot = dict(base, **{"@panda:panda_hand_tcp": translation(0.0, 0.0, 0.06)})
    assert holds(P("aligned", "gripper", "pot", within=0.03), _scope(world, near_pot))
    assert not holds(P("aligned", "gripper", "pot", within=0.03), _scope(world))
    over_glass = dict(base, **{HAND: translation(-0.2, -0.25, 0.14)})
    assert holds(P("near", "gripper", "glass", within=0.05), _scope(world, over_glass))
    assert not holds(P("near", "gripper", "glass", within=0.01), _scope(world, over_glass))
    assert holds(P("touching", "gripper", "glass"), _scope(world, last_contacts={(HAND, "glass"): [1, 0, 0]}))
    assert not holds(P("touching", "gripper", "glass"), _scope(world))
    in_zone = dict(base, **{HAND: translation(0.3, -0.2, 0.01)})
    assert holds(P("touching", "gripper", "stove"), _scope(world, in_zone))


def test_condition_trees(world):
    s = _scope(world)
    up = P("upright", "glass")
    assert holds(AllOf(items=(up, Not(item=P("lifted", "pot")))), s)
    assert holds(AnyOf(items=(P("lifted", "pot"), up)), s)
    assert not holds(Not(item=up), s)


def test_opened_and_closed_read_the_part_joint():
    path = REPO / "scenarios" / "temporal" / "open_drawer_then_insert.fsv"
    scenario = ScenarioLoader(allowed_roots=[REPO / "scenarios"]).load(path).scenario
    scene = lower_scene(scenario)
    spec = lower_monitor(scenario, scene)
    layout = build_layout(spec, scene)
    geometry = build_geometry(scene, layout, {})
    part = layout.bodies["cabinet"].parts[0]
    span = part.upper - part.lower

    def scope(fraction: float) -> Scope:
        return Scope(state({}, joints={part.joint: part.lower + fraction * span}), layout, geometry)

    assert holds(P("opened", "cabinet", fraction=0.6), scope(0.7))
    assert not holds(P("opened", "cabinet", fraction=0.6), scope(0.5))
    assert holds(P("closed", "cabinet", fraction=0.1), scope(0.05))
    assert not holds(P("closed", "cabinet", fraction=0.1), scope(0.5))


def test_predicates_that_say_the_same_thing_are_evaluated_once_a_step(world, monkeypatch):
    from fsvla.monitor.predicates import predicate_slots

    calls = []
    lifted = EVALUATORS["lifted"]
    monkeypatch.setitem(EVALUATORS, "lifted", lambda p, s: calls.append(p) or lifted(p, s))
    first, again, other = P("lifted", "pot", by=0.03), P("lifted", "pot", by=0.03), P("lifted", "pot", by=0.05)
    condition = AllOf(items=(first, Not(item=other)))
    slots = predicate_slots(condition, AnyOf(items=(again,)))
    assert slots[id(first)] == slots[id(again)] != slots[id(other)]
    base = world[1]
    up = dict(base, pot=base["pot"] @ translation(0, 0, 0.04))
    evaluator, _ = world
    scope = _scope(world, up)
    scope = Scope(scope.state, evaluator.layout, evaluator.geometry, slots)
    calls.clear()  # what the evaluator's reset asked
    assert holds(condition, scope) and holds(again, scope)
    assert calls == [first, other]  # `again` took `first`'s answer
    scope = _scope(world, up)
    calls.clear()
    assert holds(condition, scope) and holds(again, scope) and len(calls) == 3  # without slots: each its own
