"""Each built-in embodiment in a physics-only SAPIEN scene (CPU, no render system).

Checks, per embodiment: it loads with the expected joints; it holds its home pose
under gravity for 500 steps (with the passive-force feed-forward, and with the PD
drives alone); each gripper reaches its open and closed targets; and each arm's TCP
reaches a 3x3x3 grid over its table work area with the gripper pointing down.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from fsvla.embodiments import builtin_embodiments, load_embodiment
from fsvla.sim.kinematics import ArmKinematics
from fsvla.sim.robot import LoadedRobot, load_robot, self_collision_bits, srdf_disabled_pairs
from tests.conftest import require_sapien

sapien = require_sapien()
pytestmark = pytest.mark.sim

HOLD_STEPS = 500
HOLD_TOL_COMPENSATED = 1e-3  # rad or m, max |q - q_home| over all joints after 500 steps
HOLD_TOL_DRIVES_ONLY = 2e-2  # same, without gravity feed-forward (PD stiffness alone)
GRIPPER_STEPS = 100
GRIPPER_TOL = 0.01  # of the joint's range (fraction), per finger joint
IK_POSITION_TOL = 0.01  # m, FK(IK(target)) vs target
IK_ROTATION_TOL = 0.02  # rad


@pytest.fixture(scope="module", params=builtin_embodiments())
def loaded(request: pytest.FixtureRequest) -> Iterator[tuple[object, LoadedRobot]]:
    scene = sapien.Scene([sapien.physx.PhysxCpuSystem()])
    robot = load_robot(scene, load_embodiment(request.param))
    yield scene, robot


@pytest.fixture
def at_home(loaded: tuple[object, LoadedRobot]) -> tuple[object, LoadedRobot]:
    scene, robot = loaded
    robot.reset_home()
    return scene, robot


def _step(scene: object, robot: LoadedRobot, n: int, compensate: bool = True) -> None:
    for _ in range(n):
        if compensate:
            robot.compensate_gravity()
        scene.step()  # type: ignore[attr-defined]


def test_loads_with_named_joints_at_home(at_home: tuple[object, LoadedRobot]) -> None:
    _, robot = at_home
    spec = robot.spec
    assert set(robot.arms) == set(spec.arm_names)
    assert set(robot.articulations) == {r.name for r in spec.robots}
    for arm in robot.arms.values():
        names = [j.name for j in arm.articulation.active_joints]
        assert [names[i] for i in arm.joint_indices] == list(arm.spec.joints)
        assert [names[i] for i in arm.gripper_indices] == list(arm.spec.gripper.joints)
        assert arm.ee_link.name == arm.spec.ee_link
        assert np.allclose(arm.qpos(), arm.spec.home, atol=1e-5)
        assert np.allclose(arm.gripper_qpos(), arm.spec.gripper.open, atol=1e-5)
    for articulation in robot.articulations.values():
        assert articulation.get_root_pose().p[2] == pytest.approx(
            next(r for r in spec.robots if r.name == articulation.name).mount.position[2], abs=1e-6
        )


@pytest.mark.parametrize("compensate", [True, False], ids=["feedforward", "drives_only"])
def test_holds_home_under_gravity(at_home: tuple[object, LoadedRobot], compensate: bool) -> None:
    scene, robot = at_home
    start = {name: a.get_qpos().copy() for name, a in robot.articulations.items()}
    _step(scene, robot, HOLD_STEPS, compensate)
    tol = HOLD_TOL_COMPENSATED if compensate else HOLD_TOL_DRIVES_ONLY
    for name, articulation in robot.articulations.items():
        drift = float(np.max(np.abs(articulation.get_qpos() - start[name])))
        assert drift < tol, f"{robot.spec.name}/{name} drifted {drift:.2e} from home"


def test_gripper_opens_and_closes(at_home: tuple[object, LoadedRobot]) -> None:
    scene, robot = at_home
    for arm in robot.arms.values():
        gripper = arm.spec.gripper
        span = np.abs(np.array(gripper.open) - np.array(gripper.closed))
        for is_open in (False, True, False):
            arm.set_gripper(is_open)
            _step(scene, robot, GRIPPER_STEPS)
            error = np.abs(arm.gripper_qpos() - np.array(gripper.targets(is_open)))
            assert np.all(error <= GRIPPER_TOL * span + 1e-4), (
                f"{robot.spec.name}/{arm.name} gripper {'open' if is_open else 'closed'}: "
                f"{arm.gripper_qpos()} vs {gripper.targets(is_open)}"
            )


def test_reaches_work_area_pointing_down(at_home: tuple[object, LoadedRobot]) -> None:
    _, robot = at_home
    for arm in robot.arms.values():
        kinematics = ArmKinematics(arm)
        down = kinematics.top_down()
        center = np.array(arm.spec.workspace.center)
        size = np.array(arm.spec.workspace.size)
        for offset in itertools.product((-0.5, 0.0, 0.5), repeat=3):
            target = tuple(center + size * np.array(offset))
            result = kinematics.inverse(target, down)
            assert result.within_limits, f"{robot.spec.name}/{arm.name} {target}: out of limits"
            assert result.position_error < IK_POSITION_TOL, (
                f"{robot.spec.name}/{arm.name} {target}: {result.position_error * 1000:.1f} mm"
            )
            assert result.rotation_error < IK_ROTATION_TOL


def test_tcp_pose_matches_kinematics(at_home: tuple[object, LoadedRobot]) -> None:
    scene, robot = at_home
    _step(scene, robot, 1)
    for arm in robot.arms.values():
        fk = ArmKinematics(arm).tcp_pose()
        assert np.allclose(arm.tcp_pose().p, fk.p, atol=1e-3)


def test_robots_of_one_embodiment_keep_separate_collision_filters() -> None:
    scene = sapien.Scene([sapien.physx.PhysxCpuSystem()])
    robot = load_robot(scene, load_embodiment("dual_panda"))
    groups = {
        name: {s.get_collision_groups()[3] for link in a.links for s in link.collision_shapes}
        for name, a in robot.articulations.items()
    }
    left, right = groups["left_panda"], groups["right_panda"]
    assert len(left) == 1 and len(right) == 1 and left != right


def test_no_robot_presses_into_itself_at_home(at_home: tuple[object, LoadedRobot]) -> None:
    """Every SRDF-disabled pair is off (SAPIEN applies only the `Default` ones: a Panda's
    hand and link 7 pressed into each other 2 cm deep, in every physics step)."""
    scene, robot = at_home
    _step(scene, robot, 5)
    links = {id(link) for a in robot.articulations.values() for link in a.links}
    touching = [(c.bodies[0].name, c.bodies[1].name, min(p.separation for p in c.points))
                for c in scene.get_contacts()  # type: ignore[attr-defined]
                if id(c.bodies[0]) in links and id(c.bodies[1]) in links]
    assert [t for t in touching if t[2] < 0.0] == []


def test_self_collision_bits_share_a_bit_exactly_for_disabled_pairs() -> None:
    links = ["a", "b", "c", "d", "e"]
    disabled = [("a", "b"), ("b", "c"), ("a", "c"), ("c", "d"), ("e", "e"), ("a", "zz")]
    bits = self_collision_bits(links, disabled)
    pairs = {frozenset(p) for p in disabled if p[0] != p[1]}
    for x, y in itertools.combinations(links, 2):
        assert bool(bits[x] & bits[y]) == (frozenset((x, y)) in pairs), (x, y)


def test_the_panda_srdf_pairs_fit_the_bits() -> None:
    from fsvla.embodiments.assets import resolve_asset

    spec = load_embodiment("panda").robots[0]
    disabled = srdf_disabled_pairs(resolve_asset(spec.srdf))
    assert ("panda_hand", "panda_link7") in disabled
    links = sorted({name for pair in disabled for name in pair})
    bits = self_collision_bits(links, disabled)
    assert max(bits.values()) < 1 << 31
    assert bits["panda_hand"] & bits["panda_link7"]
    assert not bits["panda_link1"] & bits["panda_hand"] or ("panda_hand", "panda_link1") in disabled


def test_a_jaw_in_convex_pieces_has_one_shape_per_piece() -> None:
    # the SO-101's fixed jaw and wrist are one mesh; as one hull they fill the jaws' gap
    from fsvla.sim.urdf import convex_piece_files

    spec = load_embodiment("so101")
    folder = Path(spec.robots[0].collision_pieces["wrist_roll_follower_so101_v1.stl"])
    scene = sapien.Scene([sapien.physx.PhysxCpuSystem()])
    robot = load_robot(scene, spec)
    link = next(lk for lk in robot.articulations["so101"].get_links() if lk.name == "gripper_link")
    # the link's other mesh (its servo) stays one hull
    assert len(link.collision_shapes) == len(convex_piece_files(folder)) + 1


def test_finger_pads_get_the_friction_their_gripper_sets(loaded: tuple[object, LoadedRobot],
                                                        ) -> None:
    # a jaw on a hinge (the Z1's) holds its load by friction alone: rubber pads; a
    # gripper that sets none keeps the simulator's default material
    _scene, robot = loaded
    default = sapien.physx.get_default_material().static_friction
    for arm in robot.arms.values():
        want = arm.spec.gripper.pad_friction
        for link in arm.finger_links:
            frictions = {round(shape.physical_material.static_friction, 6)
                         for shape in link.collision_shapes}
            assert frictions == {round(want if want is not None else default, 6)}, link.name
