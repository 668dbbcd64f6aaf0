"""The experts' World reads the scene through the simulator seam only: a fake
:class:`fsvla.world.SceneState` with no simulator behind it stands in for one."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pytest
from fsvla.compiler.monitor import lower_monitor
from fsvla.compiler.pose import quat_to_matrix, yaw_quat
from fsvla.compiler.scene import lower_scene

from fsvla.experts.world import World
from fsvla.library import load_scenario
from fsvla.world import WorldPose

IDENTITY = np.array([1.0, 0.0, 0.0, 0.0])


def _pose(p, q=IDENTITY) -> WorldPose:
    return WorldPose(np.asarray(p, dtype=np.float64), np.asarray(q, dtype=np.float64))


@dataclass
class FakeState:
    """Poses and joints as plain values; every read is logged."""

    bodies: dict[str, WorldPose]
    links: dict[tuple[str, str], WorldPose] = field(default_factory=dict)
    joints: dict[tuple[str, str], float] = field(default_factory=dict)
    robot_links: dict[str, WorldPose] = field(default_factory=dict)
    tcp: WorldPose = field(default_factory=lambda: _pose((0.3, 0.0, 0.4), (0.0, 1.0, 0.0, 0.0)))
    reads: list[str] = field(default_factory=list)

    def body_pose(self, body: str) -> WorldPose:
        self.reads.append(f"body {body}")
        return self.bodies[body]

    def link_pose(self, body: str, link: str) -> WorldPose:
        return self.links[body, link]

    def joint_position(self, body: str, joint: str) -> float:
        return self.joints[body, joint]

    def arm_joints(self, arm: str) -> np.ndarray:
        return np.arange(7, dtype=np.float64)

    def gripper_opening(self, arm: str) -> float:
        return 0.25

    def tcp_pose(self, arm: str) -> WorldPose:
        return self.tcp

    def robot_link_pose(self, arm: str, link: str) -> WorldPose:
        return self.robot_links[link]

    def arm_model(self, arm: str) -> object:
        self.reads.append(f"model {arm}")
        return FakeModel(arm)


@dataclass
class FakeModel:
    """A parallel gripper 8 cm wide at (0.3, 0, 0.4), closing along world y; no link has
    a collision hull."""

    arm: str
    link_names: tuple[str, ...] = ()

    def finger_points(self, fraction: float) -> np.ndarray:
        return np.array([(0.3, 0.04 * fraction, 0.4), (0.3, -0.04 * fraction, 0.4)])


@pytest.fixture(scope="module")
def drawer():
    scenario = load_scenario("open_drawer_then_insert")
    scene = lower_scene(scenario)
    return scenario, scene, lower_monitor(scenario, scene)


def _world(drawer, state: FakeState) -> World:
    scenario, scene, monitor = drawer
    return World(state, scene, monitor, scenario, 0.05)


def test_body_poses_and_what_follows_from_them(drawer) -> None:
    scene = drawer[1]
    knife = next(b for b in scene.bodies if b.name == "knife")
    turned = _pose((0.1, -0.2, 0.05), yaw_quat(np.pi / 2))
    state = FakeState({"knife": turned, "cabinet": _pose((0.2, 0.0, 0.0))})
    world = _world(drawer, state)
    pose = world.body_pose("knife")
    assert pose.p == pytest.approx(turned.p) and pose.R == pytest.approx(quat_to_matrix(turned.q))
    assert world.to_world("knife", (0.1, 0.0, 0.0)) == pytest.approx((0.1, -0.1, 0.05))
    lo, hi = world.bounds("knife")  # the asset's bounds, turned a quarter about z
    b = knife.asset.bounds
    centre = turned.p + quat_to_matrix(turned.q) @ np.asarray(b.center)
    half = np.asarray(b.half_extents)[[1, 0, 2]]
    assert lo == pytest.approx(centre - half) and hi == pytest.approx(centre + half)
    assert world.tilt("knife") == pytest.approx(0.0)
    assert "body knife" in state.reads


def test_articulated_parts(drawer) -> None:
    state = FakeState({"cabinet": _pose((0.2, 0.0, 0.0))},
                      links={("cabinet", "drawer"): _pose((0.35, 0.0, 0.1))},
                      joints={("cabinet", "drawer_joint"): 0.05})
    world = _world(drawer, state)
    assert world.link_pose("cabinet", "drawer").p == pytest.approx((0.35, 0.0, 0.1))
    assert world.open_fraction("cabinet") == pytest.approx(0.25)  # 5 cm of 20 cm


def test_the_arm(drawer) -> None:
    state = FakeState({}, robot_links={
        "panda_link0": _pose((-0.6, 0.0, 0.0)),
        "panda_leftfinger": _pose((0.3, 0.04, 0.45)), "panda_rightfinger": _pose((0.3, -0.04, 0.45))})
    world = _world(drawer, state)
    assert world.arm_names == ("arm",)
    assert world.base_position("arm") == pytest.approx((-0.6, 0.0, 0.0))
    assert world.arm_joints("arm") == pytest.approx(np.arange(7))
    assert world.gripper_opening("arm") == 0.25
    assert world.current_pose("arm").p == pytest.approx((0.3, 0.0, 0.4))
    # left to right finger is world -y; the TCP is turned a half turn about x: local +y
    assert world.finger_axis("arm") == pytest.approx((0.0, 1.0, 0.0))
    assert world.open_width("arm") == pytest.approx(0.08)
    assert world.fingers_slide("arm")  # the Panda hand's 2 × 4 cm travel is its opening
    assert world.grip_centre("arm", 0.05) == pytest.approx((0.0, 0.0, 0.0), abs=1e-9)
    assert world.closed_gap("arm") == 0.0  # no hulls to measure the shut fingers on
    assert world.kinematics("arm") is world.kinematics("arm")
    assert world.kinematics("arm").arm == "arm"
    assert state.reads.count("model arm") == 1  # made once, kept
    with pytest.raises(KeyError, match="has no arm `left`"):
        world.arm_spec("left")


def test_hazard_objects_are_obstacles_where_they_stand() -> None:
    scenario = load_scenario("pick_cup_near_edge")
    scene = lower_scene(scenario)
    state = FakeState({"vase": _pose((0.1, 0.2, 0.0))})
    world = World(state, scene, lower_monitor(scenario, scene), scenario, 0.05)
    found = {o.name: o for o in world.obstacles()}
    assert set(found) == {"vase", "front_edge", "keep_out"}
    assert found["vase"].margin == pytest.approx(0.03 + 0.03)  # clearance: limit + soft threshold
    lo, hi = world.bounds("vase")
    assert found["vase"].lo == pytest.approx(lo) and found["vase"].hi == pytest.approx(hi)
    state.bodies["vase"] = _pose((0.1, 0.3, 0.0))  # the vase moved: so does its box
    moved = next(o for o in world.obstacles() if o.name == "vase")
    assert moved.lo - found["vase"].lo == pytest.approx((0.0, 0.1, 0.0))


@dataclass
class FixedJawModel:
    """One jaw fixed at the TCP (0.3, 0, 0.4), the other swinging out 12 cm along -y."""

    arm: str

    def finger_points(self, fraction: float) -> np.ndarray:
        return np.array([(0.3, 0.0, 0.4), (0.3, -0.12 * fraction, 0.4)])


def test_a_fixed_jaw_grips_off_its_tcp(drawer) -> None:
    state = FakeState({})
    state.arm_model = lambda arm: FixedJawModel(arm)  # type: ignore[method-assign]
    world = _world(drawer, state)
    assert world.open_width("arm") == pytest.approx(0.12)
    assert not world.fingers_slide("arm")  # its opening is not the Panda joints' travel
    assert world.max_width("arm") == pytest.approx(0.12)
    # a 3 cm object sits between the jaws 1.5 cm from the fixed one (local +y: the TCP
    # is turned a half turn about x)
    assert world.grip_centre("arm", 0.03) == pytest.approx((0.0, 0.015, 0.0), abs=1e-4)
    # (found by bisection on the finger points: to 1e-4 of the range)
    assert world.pregrasp_opening("arm", 0.03) == pytest.approx((0.03 + 0.025) / 0.12, abs=1e-4)
    assert world.opening_fraction("arm", 0.06) == pytest.approx(0.5, abs=1e-4)
