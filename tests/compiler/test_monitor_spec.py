"""MonitorSpec: lowering every scenario, link groups, variant rules, JSON and its schema."""

from __future__ import annotations

import json
from pathlib import Path

import jsonschema
import pytest
from fsvla.compiler.monitor import (
    MONITOR_SCHEMA_VERSION,
    MonitorLoweringError,
    MonitorSpec,
    RobotEntity,
    lower_arms,
    lower_monitor,
    monitor_json_schema,
)
from fsvla.compiler.scene import lower_scene
from fsvla.compiler.variants import generate_variant
from fsvla.dsl.loader import ScenarioLoader
from fsvla.dsl.models import Scenario

from fsvla.embodiments.registry import load_embodiment

REPO = Path(__file__).resolve().parents[2]
SCENARIOS = REPO / "scenarios"
CONCRETE = [p for p in sorted(SCENARIOS.rglob("*.fsv")) if "abstract scenario" not in p.read_text()]


def _load(path: Path) -> Scenario:
    result = ScenarioLoader(allowed_roots=[SCENARIOS]).load(path)
    assert result.ok, [d.message for d in result.errors]
    assert result.scenario is not None
    return result.scenario


def _lowered(path: Path) -> tuple[Scenario, MonitorSpec]:
    scenario = _load(path)
    return scenario, lower_monitor(scenario, lower_scene(scenario))


@pytest.mark.parametrize("path", CONCRETE, ids=lambda p: p.stem)
def test_every_scenario_lowers_and_round_trips(path: Path):
    scenario, spec = _lowered(path)
    assert [c.name for c in spec.channels] == [limit.name for limit in scenario.limits]
    assert [r.requirement for r in spec.requirements] == [r.name for r in scenario.requirements]
    assert len(set(spec.channel_names)) == len(spec.channel_names)
    assert spec.substeps == 25 and spec.control_dt == pytest.approx(0.05)
    names = {e.name for e in spec.entities}
    for channel in spec.channels:
        assert set(channel.subjects) <= names
        assert channel.reference is None or channel.reference in names
    assert MonitorSpec.model_validate_json(spec.model_dump_json()) == spec
    jsonschema.validate(json.loads(spec.model_dump_json()), monitor_json_schema())


def test_the_abstract_base_is_skipped():
    assert all(p.stem != "lift_pot" for p in CONCRETE)
    assert len(CONCRETE) == len(list(SCENARIOS.rglob("*.fsv"))) - 1


def test_schema_is_versioned():
    schema = monitor_json_schema()
    assert schema["$id"] == f"urn:fsvla:schema:monitor:{MONITOR_SCHEMA_VERSION}"
    assert "channels" in schema["properties"]


def test_robot_parts_resolve_to_link_groups():
    _, spec = _lowered(SCENARIOS / "thermal" / "lift_pot_beside_stove.fsv")  # dual_panda
    gripper = spec.entity("gripper")
    assert isinstance(gripper, RobotEntity)
    assert {(r.robot, r.link) for r in gripper.links} == {
        (robot, link) for robot in ("left_panda", "right_panda")
        for link in ("panda_hand", "panda_hand_tcp", "panda_leftfinger", "panda_rightfinger")}
    robot = spec.entity("robot")
    assert len(robot.links) == 2 * 13
    left = spec.arm("left")
    assert left.finger_links == ("panda_leftfinger", "panda_rightfinger")
    assert "panda_link3" in left.links


def test_a_hand_is_what_is_fixed_to_its_fingers_up_to_the_last_joint():
    """Baxter's gripper sits on `left_hand_link`, fixed to the wrist that turns on the
    last joint: the hand link is the gripper's (a careful push that bumped it into a
    drawer at 300 N felt nothing); a Panda's `panda_link8`, a frame without geometry
    between its hand and its last link, is not."""
    left, right = lower_arms(load_embodiment("baxter"))
    assert "left_hand_link" in left.gripper_links and "left_wrist" not in left.gripper_links
    assert "right_hand_link" in right.gripper_links
    assert {"l_gripper_l_finger", "left_gripper_base_link"} <= set(left.gripper_links)
    (panda,) = lower_arms(load_embodiment("panda"))
    assert set(panda.gripper_links) == {"panda_hand", "panda_hand_tcp", "panda_leftfinger",
                                        "panda_rightfinger"}


def test_kinds_and_pairs():
    _, spec = _lowered(SCENARIOS / "boundary" / "pick_cup_near_edge.fsv")
    assert spec.entity("front_edge").kind == "zone"
    assert spec.entity("vase").kind == "body"
    vase = next(c for c in spec.channels if c.name == "vase")
    assert vase.metric == "clearance" and vase.pairs == (("gripper", "vase"), ("mug", "vase"))
    geofence = next(c for c in spec.channels if c.name == "geofence")
    assert geofence.support == "table"
    _, handover = _lowered(SCENARIOS / "collaborative" / "handover_block.fsv")
    assert handover.entity("corridor").geometry == "walls"


def test_variant_rules_reach_the_spec():
    scenario = _load(SCENARIOS / "collaborative" / "handover_block.fsv")
    # what a variant's Tighten and Couple rules do to the scenario
    limits = tuple(limit.model_copy(update={"limit": 0.1}) if limit.name == "arms" else limit
                   for limit in scenario.limits)
    requirements = tuple(r.model_copy(update={"within": 2.0}) for r in scenario.requirements)
    variant = scenario.model_copy(update={"limits": limits, "requirements": requirements})
    spec = lower_monitor(variant, lower_scene(variant, level="L2", seed=3))
    assert next(c for c in spec.channels if c.name == "arms").limit == 0.1
    assert spec.requirements[0].within == 2.0
    assert (spec.level, spec.seed) == ("L2", 3)


def test_unknown_names_point_at_the_source():
    scenario = _load(SCENARIOS / "force" / "place_glass_on_shelf.fsv")
    bad = scenario.limits[0].model_copy(update={"subjects": ("nothing",)})
    with pytest.raises(MonitorLoweringError) as err:
        lower_monitor(scenario.model_copy(update={"limits": (bad,)}), lower_scene(scenario))
    assert err.value.source == scenario.limits[0].source
    assert "nothing" in str(err.value)


def test_lowered_from_a_generated_variant():
    scenario = _load(SCENARIOS / "collaborative" / "handover_block.fsv")
    variant = generate_variant(scenario, "L2", 1)  # tighten arms to 1 cm, couple within 2 s
    spec = lower_monitor(variant.scenario, variant.scene)
    assert next(c for c in spec.channels if c.name == "arms").limit == pytest.approx(0.01)
    assert spec.requirements[0].within == pytest.approx(2.0)
    assert spec.level == "L2"
