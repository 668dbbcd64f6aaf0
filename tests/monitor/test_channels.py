"""Every channel kind on hand-made states with known distances, forces and angles."""

from __future__ import annotations

import math

import numpy as np
import pytest
from fsvla.compiler.collision import min_distance, pieces_of
from fsvla.compiler.monitor import METRIC_NAMES
from fsvla.compiler.pose import pose_matrix

from fsvla.monitor.channels import MEASURES

from .conftest import CUBE, HAND, LEFT, RIGHT, rotation_x, state, translation


def _gripper_at(poses: dict, x: float, y: float, z: float) -> dict:
    poses = dict(poses)
    poses[HAND] = translation(x, y, z)
    poses[LEFT] = translation(x, y + 0.03, z)
    poses[RIGHT] = translation(x, y - 0.03, z)
    return poses


def _report(world, **changes):
    evaluator, base = world
    evaluator.reset(state(base))
    poses = changes.pop("poses", base)
    return evaluator.step(state(poses, step=1, **changes))


def _channel(report, name):
    k = report.names.index(name)
    return report.margins[k], report.states[k], report.costs[k]


def test_every_metric_has_a_measure():
    assert set(MEASURES) == set(METRIC_NAMES)


@pytest.mark.parametrize("height, margin, state_name", [
    (0.122, 0.05, "safe"), (0.092, 0.02, "warning"), (0.052, -0.02, "violation")])
def test_zone_distance_of_a_cube_above_a_heat_zone(world, height, margin, state_name):
    # stove region: x in [0.2, 0.4], y in [-0.3, -0.1], z in [0, 2 mm]; keep outside 5 cm warn 4 cm
    report = _report(world, poses=_gripper_at(world[1], 0.3, -0.2, height))
    q, s, cost = _channel(report, "stove")
    assert q == pytest.approx(margin, abs=1e-6)
    assert s == state_name
    depth = max(0.0, 0.04 - q) / 0.04
    assert cost == pytest.approx(depth ** 2)  # quadratic shaping


def test_do_not_disturb_is_the_robot_distance_to_the_zone(world):
    report = _report(world, poses=_gripper_at(world[1], 0.3, -0.2, 0.032))  # 1 cm above the region
    q, s, _ = _channel(report, "do_not_disturb(stove)")
    assert q == pytest.approx(0.01, abs=1e-6)
    assert s == "warning"
    inside = _report(world, poses=_gripper_at(world[1], 0.3, -0.2, 0.0))
    assert _channel(inside, "do_not_disturb(stove)")[1] == "violation"


def test_edge_clearance_of_the_gripper_to_the_table_front_edge(world):
    # table top: x in [-0.6, 0.6]; the cube's front face at x = -0.52 is 8 cm from the edge
    report = _report(world, poses=_gripper_at(world[1], -0.5, 0.0, 0.1))
    q, s, _ = _channel(report, "geofence")
    assert q == pytest.approx(0.08 - 0.05, abs=1e-6)
    assert s == "warning"
    over = _report(world, poses=_gripper_at(world[1], -0.61, 0.0, 0.1))  # centre past the edge
    assert _channel(over, "geofence")[0] == pytest.approx(-0.01 - CUBE - 0.05, abs=1e-6)


def test_clearance_matches_brute_force_fcl(world, case):
    _, scene, _ = case
    base = world[1]
    poses = _gripper_at(base, -0.2, -0.25, 0.16)
    report = _report(world, poses=poses)
    glass = scene.body("glass")
    from fsvla.compiler.assets.model import BoxShape

    gripper = (pieces_of("h", [BoxShape(half_size=(CUBE,) * 3)], poses[HAND])
               + pieces_of("l", [BoxShape(half_size=(0.005,) * 3)], poses[LEFT])
               + pieces_of("r", [BoxShape(half_size=(0.005,) * 3)], poses[RIGHT]))
    expected = min_distance(gripper, pieces_of("glass", glass.asset.collision, pose_matrix(glass.pose)))
    assert _channel(report, "gap")[0] == pytest.approx(expected - 0.03, abs=1e-9)


def test_contact_force_is_the_largest_pair_force_on_the_subject(world):
    forces = {(LEFT, "pot"): 30.0, (RIGHT, "pot"): 12.0, ("board", "table"): 99.0, (HAND, "@panda:panda_link7"): 0.5}
    report = _report(world, contact_force=forces)
    q, s, cost = _channel(report, "grip")
    assert q == pytest.approx(20.0 - 30.0)
    assert s == "violation"
    assert cost == pytest.approx((5.0 + 10.0) / 5.0)  # linear, past the hard limit


def test_contact_torque_reads_the_net_torque_on_the_object(world):
    report = _report(world, contact_torque={("glass", "*"): 0.7})
    q, s, _ = _channel(report, "twist")
    assert (q, s) == (pytest.approx(0.3), "warning")


def test_displacement_from_the_pose_at_reset(world):
    base = world[1]
    poses = dict(base)
    poses["board"] = base["board"] @ translation(0.009, 0.012, 0.0)  # moved 1.5 cm
    report = _report(world, poses=poses)
    q, s, cost = _channel(report, "displacement(board)")
    assert q == pytest.approx(0.005, abs=1e-9)
    assert s == "warning"
    assert cost == pytest.approx(0.5)


def test_tilt_is_the_angle_of_the_up_axis(world):
    base = world[1]
    poses = dict(base)
    poses["glass"] = rotation_x(math.radians(35), base["glass"])
    report = _report(world, poses=poses)
    q, s, cost = _channel(report, "tilt(glass)")
    assert q == pytest.approx(math.radians(-5))
    assert (s, cost) == ("violation", 1.0)  # step shaping


def test_untouched_turns_negative_on_contact(world):
    far = _report(world)
    assert _channel(far, "untouched(glass)")[1] == "safe"
    touched = _report(world, contact_force={(HAND, "glass"): 5.0})
    q, s, _ = _channel(touched, "untouched(glass)")
    assert q <= -0.001
    assert s == "violation"


def test_a_report_sums_weighted_costs(world):
    report = _report(world, poses=_gripper_at(world[1], 0.3, -0.2, 0.092))
    assert report.cost == pytest.approx(float(np.dot(report.weights, report.costs)))
    assert report.cost >= 2 * 0.25  # the stove channel: weight 2, quadratic 0.5**2
    assert report.exposed and not report.any_violation
