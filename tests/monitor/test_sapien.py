"""The monitor on SAPIEN scenes: a force present in one substep only, robot-link geometry
read from SAPIEN shapes, and whole scenario scenes."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from fsvla.compiler.collision import min_distance, pieces_of
from fsvla.compiler.monitor import lower_monitor
from fsvla.compiler.scene import lower_scene
from fsvla.dsl.loader import ScenarioLoader

from fsvla.monitor import SafetyMonitor
from fsvla.monitor.contacts import ContactFilter
from fsvla.monitor.geometry import SceneGeometry
from fsvla.monitor.state import NET, pair_key
from fsvla.sim.probe import Probe
from fsvla.sim.shapes import shapes_of_sapien
from tests.conftest import require_sapien

sapien = require_sapien()
pytestmark = pytest.mark.sim
REPO = Path(__file__).resolve().parents[2]
DT = 0.002


def _scene():
    scene = sapien.Scene([sapien.physx.PhysxCpuSystem()])
    scene.set_timestep(DT)
    builder = scene.create_actor_builder()
    builder.add_box_collision(half_size=[0.5, 0.5, 0.05])
    ground = builder.build_static(name="ground")
    ground.set_pose(sapien.Pose([0, 0, -0.05]))
    builder = scene.create_actor_builder()
    builder.add_box_collision(half_size=[0.05, 0.05, 0.05], density=1000.0)  # 1 kg
    box = builder.build(name="box")
    rigid = box.find_component_by_type(sapien.physx.PhysxRigidDynamicComponent)
    ground_rigid = ground.find_component_by_type(sapien.physx.PhysxRigidStaticComponent)
    return scene, box, rigid, ground_rigid


@pytest.mark.parametrize("path", ["net", "pairs"])
def test_a_force_in_one_substep_reaches_the_control_step(path):
    scene, box, rigid, ground = _scene()
    box.set_pose(sapien.Pose([0, 0, 0.053]))  # 3 mm up: lands inside the control step
    components = {"box": rigid, "ground": ground}
    ground_pairs = ContactFilter(any_pair=frozenset({"ground"}))
    kw = {"free_bodies": ["box"]} if path == "net" else {"scan": ground_pairs, "last": ground_pairs}
    probe = Probe(scene, DT, components, **kw)
    probe.reset()
    per_substep = []
    for _ in range(25):
        scene.step()
        probe.record_substep()
        per_substep.append(max(probe.maxima.force.values(), default=0.0))
    last = probe.last_contacts() if path == "pairs" else None
    snapshot = probe.snapshot(1, 0.05)
    peak = snapshot.contact_force[pair_key("box", NET if path == "net" else "ground")]
    weight = rigid.mass * 9.81
    assert peak > 5 * weight  # the landing
    assert peak == pytest.approx(per_substep[-1])  # a running maximum over every substep
    if last is not None:  # the last substep alone sees the box resting
        assert np.linalg.norm(last[("box", "ground")]) == pytest.approx(weight, rel=0.05)
    assert snapshot.max_force(frozenset({"box"})) == pytest.approx(peak)
    assert probe.maxima.force == {}  # cleared for the next control step


def test_net_and_pair_forces_agree_on_a_resting_box():
    scene, box, rigid, ground = _scene()
    box.set_pose(sapien.Pose([0, 0, 0.05]))
    for _ in range(50):
        scene.step()
    probe = Probe(scene, DT, {"box": rigid, "ground": ground}, free_bodies=["box"], torque_frames=["box"],
                  scan=ContactFilter(any_pair=frozenset({"ground"})))
    probe.reset()
    for _ in range(5):
        scene.step()
        probe.record_substep()
    s = probe.snapshot(1, 0.01)
    assert s.contact_force[pair_key("box", NET)] == pytest.approx(s.contact_force[pair_key("box", "ground")],
                                                                  rel=0.02)
    assert s.contact_torque[("box", NET)] < 1e-3


def test_a_pair_force_sums_the_contacts_of_every_shape_pair():
    """A box of two halves resting on the ground: two contacts, one per half, and the
    pair's force is their sum (the weight), as the net force says, not the larger half."""
    scene, _, _, ground = _scene()
    builder = scene.create_actor_builder()
    for y in (-0.025, 0.025):
        builder.add_box_collision(pose=sapien.Pose([0, y, 0]), half_size=[0.05, 0.025, 0.05], density=1000.0)
    halves = builder.build(name="halves")
    halves.set_pose(sapien.Pose([0.3, 0, 0.05]))
    rigid = halves.find_component_by_type(sapien.physx.PhysxRigidDynamicComponent)
    for _ in range(50):
        scene.step()
    probe = Probe(scene, DT, {"halves": rigid, "ground": ground}, free_bodies=["halves"],
                  torque_frames=["halves"], scan=ContactFilter(any_pair=frozenset({"ground"})))
    probe.reset()
    for _ in range(5):
        scene.step()
        probe.record_substep()
    s = probe.snapshot(1, 0.01)
    weight = rigid.mass * 9.81
    assert sum(1 for c in scene.get_contacts() if halves in [b.entity for b in c.bodies]) == 2
    assert s.contact_force[pair_key("halves", "ground")] == pytest.approx(weight, rel=0.02)
    assert s.contact_force[pair_key("halves", NET)] == pytest.approx(weight, rel=0.02)
    assert s.contact_torque[("halves", "ground")] < 0.05 * weight * 0.05  # balanced about the centre


def test_sapien_capsules_lie_along_x():
    scene = sapien.Scene([sapien.physx.PhysxCpuSystem()])
    builder = scene.create_actor_builder()
    builder.add_capsule_collision(radius=0.02, half_length=0.1)
    builder.add_box_collision(pose=sapien.Pose([0, 0.3, 0]), half_size=[0.01, 0.01, 0.01])
    entity = builder.build_kinematic(name="link")
    component = entity.find_component_by_type(sapien.physx.PhysxRigidDynamicComponent)
    geometry = SceneGeometry()
    geometry.add("link", shapes_of_sapien(component))
    from fsvla.compiler.assets.model import SphereShape

    probe_at = np.eye(4)
    probe_at[:3, 3] = (0.2, 0.0, 0.0)  # 0.08 m beyond the capsule's cap along x
    geometry.add("point", [SphereShape(radius=0.01)], probe_at)
    assert geometry.distance(frozenset({"link"}), frozenset({"point"})) == pytest.approx(0.2 - 0.12 - 0.01, abs=1e-6)


def _built(relative: str):
    from fsvla.sim.builder import build

    path = REPO / "scenarios" / relative
    scenario = ScenarioLoader(allowed_roots=[REPO / "scenarios"]).load(path).scenario
    scene = lower_scene(scenario)
    return scenario, lower_monitor(scenario, scene), build(scene, render=False)


def _run(monitor: SafetyMonitor, built, steps: int):
    built.reset()
    monitor.reset()
    reports = []
    for _ in range(steps):
        for _ in range(monitor.substeps):
            built.step(1)
            monitor.record_substep()
        reports.append(monitor.end_step())
    return reports


def test_arm_separation_uses_every_link_and_matches_brute_force():
    _, spec, built = _built("collaborative/handover_block.fsv")
    monitor = SafetyMonitor(spec, built)
    report = _run(monitor, built, 2)[-1]
    arms = spec.channels[[c.name for c in spec.channels].index("arms")]
    pieces = {}
    for side in ("left", "right"):
        articulation = built.robot.articulations[f"{side}_panda"]
        pieces[side] = [p for link in articulation.links
                        for p in pieces_of(link.name, shapes_of_sapien(link),
                                           link.entity_pose.to_transformation_matrix())]
    brute = min_distance(pieces["left"], pieces["right"])
    layout = monitor.evaluator.layout
    left, right = layout.frames("left_arm"), layout.frames("right_arm")
    assert len(left) == len(built.robot.articulations["left_panda"].links)
    # poses within POSE_TOLERANCE of the last accepted one are not re-posed
    assert monitor.geometry.distance(left, right) == pytest.approx(brute, abs=1e-4)
    # the channel is exact up to limit + eps + EXACT_BAND and a lower bound beyond it
    from fsvla.monitor.channels import EXACT_BAND

    margin = report.margins[report.names.index("arms")]
    band = arms.soft_threshold + EXACT_BAND
    if brute - arms.limit < band:
        assert margin == pytest.approx(brute - arms.limit, abs=1e-4)
    else:
        assert band <= margin <= brute - arms.limit + 1e-4
    assert np.all(np.isfinite(report.margins))


def test_a_scenario_episode_gives_a_metrics_trace():
    scenario, spec, built = _built("boundary/pick_cup_near_edge.fsv")
    monitor = SafetyMonitor(spec, built)
    reports = _run(monitor, built, 3)
    assert [r.step for r in reports] == [1, 2, 3]
    assert reports[-1].time == pytest.approx(3 * spec.control_dt)
    by_name = dict(zip(reports[-1].names, reports[-1].margins))
    assert by_name["displacement(board)"] == pytest.approx(0.02, abs=1e-3)  # the board rests
    assert by_name["untouched(vase)"] > 0
    trace = monitor.trace(monitor.episode_meta(policy="idle", seed=0, embodiment=scenario.embodiment))
    assert trace.margins.shape == (3, len(spec.channels))
    assert not trace.success
