"""fsvla.compiler.pose: the (w, x, y, z) order, round trips, yaw, look-at and pose
composition, held to scipy's Rotation, to closed-form rotation matrices, and to numbers
the helpers it replaced gave."""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest
from fsvla.compiler.assets.model import Pose
from fsvla.compiler.pose import (
    AXES,
    axis_angle_matrix,
    axis_angle_quat,
    look_along_quat,
    look_at_quat,
    matrix_to_quat,
    point_axis,
    pose_matrix,
    quat_mul,
    quat_to_matrix,
    quat_yaw,
    rotate_xy,
    rotation_angle,
    rotation_between,
    rpy_quat,
    slerp,
    transform_points,
    yaw_matrix,
    yaw_quat,
)
from scipy.spatial.transform import Rotation

RNG = np.random.default_rng(7)
QUATS = [q / np.linalg.norm(q) for q in RNG.normal(size=(50, 4))]


def _closed_form(q) -> np.ndarray:
    """The textbook matrix of a unit (w, x, y, z) quaternion."""
    w, x, y, z = np.asarray(q, dtype=float) / np.linalg.norm(q)
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ])


# --- the order convention ---------------------------------------------------------------


def test_quaternions_are_scalar_first() -> None:
    half = math.sqrt(0.5)
    quarter_turn_about_z = (half, 0.0, 0.0, half)  # (w, x, y, z)
    assert np.allclose(quat_to_matrix(quarter_turn_about_z) @ [1, 0, 0], [0, 1, 0])
    assert np.allclose(quat_to_matrix((1.0, 0.0, 0.0, 0.0)), np.eye(3))
    # scipy's default (x, y, z, w) order, read as ours, is another rotation
    assert not np.allclose(quat_to_matrix((0.0, 0.0, half, half)), quat_to_matrix(quarter_turn_about_z))


@pytest.mark.parametrize("q", QUATS[:10])
def test_quat_to_matrix_agrees_with_the_closed_form_and_scipy(q) -> None:
    assert np.allclose(quat_to_matrix(q), _closed_form(q), atol=1e-12)
    assert np.allclose(quat_to_matrix(2.5 * q), _closed_form(q), atol=1e-12)  # normalised
    xyzw = [q[1], q[2], q[3], q[0]]
    assert np.allclose(quat_to_matrix(q), Rotation.from_quat(xyzw).as_matrix(), atol=1e-12)


def test_quat_to_matrix_takes_a_batch() -> None:
    batch = quat_to_matrix(np.array(QUATS[:5]))
    assert batch.shape == (5, 3, 3)
    for q, m in zip(QUATS[:5], batch):
        assert np.allclose(m, _closed_form(q), atol=1e-12)


# --- round trips ------------------------------------------------------------------------


@pytest.mark.parametrize("q", QUATS)
def test_matrix_quat_round_trip_with_w_non_negative(q) -> None:
    back = matrix_to_quat(quat_to_matrix(q))
    assert back[0] >= 0.0
    assert np.allclose(back, q if q[0] >= 0 else -q, atol=1e-12)
    m = quat_to_matrix(q)
    assert np.allclose(quat_to_matrix(matrix_to_quat(m)), m, atol=1e-12)


@pytest.mark.parametrize("angle", [-7.0, -math.pi, -0.3, 0.0, 0.7, math.pi, 4.0])
def test_axis_angle_quat_and_matrix_agree(angle: float) -> None:
    axis = np.array([0.3, -1.2, 0.5])
    q = axis_angle_quat(axis, angle)
    assert np.allclose(quat_to_matrix(q), axis_angle_matrix(axis, angle), atol=1e-12)
    unit = axis / np.linalg.norm(axis)
    k = np.array([[0, -unit[2], unit[1]], [unit[2], 0, -unit[0]], [-unit[1], unit[0], 0]])
    rodrigues = np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * k @ k
    assert np.allclose(axis_angle_matrix(axis, angle), rodrigues, atol=1e-12)
    # the sign the half-angle formula gives (specs keep it): w = cos(angle / 2)
    assert q[0] == pytest.approx(math.cos(angle / 2), abs=1e-12)


def test_quat_mul_is_the_hamilton_product_and_composes_matrices() -> None:
    for a, b in zip(QUATS[:10], QUATS[10:20]):
        w1, x1, y1, z1 = a
        w2, x2, y2, z2 = b
        hamilton = (w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2, w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
                    w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2, w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2)
        assert np.allclose(quat_mul(a, b), hamilton, atol=1e-12)
        assert np.allclose(quat_to_matrix(quat_mul(a, b)), quat_to_matrix(a) @ quat_to_matrix(b))


def test_rpy_is_urdf_fixed_axes() -> None:
    roll, pitch, yaw = 0.2, -0.4, 1.1
    expected = (axis_angle_matrix((0, 0, 1), yaw) @ axis_angle_matrix((0, 1, 0), pitch)
                @ axis_angle_matrix((1, 0, 0), roll))
    q = rpy_quat((roll, pitch, yaw))
    assert q[0] >= 0
    assert np.allclose(quat_to_matrix(q), expected, atol=1e-12)


# --- yaw --------------------------------------------------------------------------------


@pytest.mark.parametrize("yaw", [-3.0, -math.pi / 2, 0.0, 0.4, math.pi / 2, 2.9, 5.0])
def test_yaw_helpers_agree_with_rotation(yaw: float) -> None:
    q = yaw_quat(yaw)
    assert q == pytest.approx((math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)))
    rotation = Rotation.from_euler("z", yaw).as_matrix()
    assert np.allclose(quat_to_matrix(q), rotation, atol=1e-12)
    assert math.remainder(quat_yaw(q) - yaw, 2 * math.pi) == pytest.approx(0.0, abs=1e-12)
    assert np.allclose(rotate_xy((0.3, -0.2), yaw), (rotation @ [0.3, -0.2, 0.0])[:2])
    m = yaw_matrix((1.0, 2.0, 3.0), yaw)
    assert np.allclose(m[:3, :3], rotation, atol=1e-12) and np.allclose(m[:3, 3], [1, 2, 3])


def test_quat_yaw_is_the_heading_of_the_x_axis() -> None:
    q = quat_mul(yaw_quat(0.8), axis_angle_quat((0, 1, 0), 0.3))  # heading 0.8, tilted
    assert quat_yaw(q) == pytest.approx(0.8)


# --- poses ------------------------------------------------------------------------------


def test_pose_matrix_places_and_turns() -> None:
    half = math.sqrt(0.5)
    m = pose_matrix(Pose(position=(1.0, 2.0, 3.0), quaternion=(half, 0.0, 0.0, half)))
    assert np.allclose(m[:3, :3] @ [1.0, 0.0, 0.0], [0.0, 1.0, 0.0])
    assert np.allclose(m[:3, 3], [1.0, 2.0, 3.0])
    assert np.allclose(m[3], [0, 0, 0, 1])


def test_pose_composition_is_matrix_product() -> None:
    a = Pose(position=(0.1, -0.2, 0.3), quaternion=tuple(QUATS[0]))
    b = Pose(position=(-0.5, 0.4, 0.0), quaternion=tuple(QUATS[1]))
    composed = Pose(
        position=tuple(quat_to_matrix(a.quaternion) @ b.position + a.position),
        quaternion=quat_mul(a.quaternion, b.quaternion),
    )
    assert np.allclose(pose_matrix(a) @ pose_matrix(b), pose_matrix(composed), atol=1e-12)


def test_transform_points_is_the_pose_matrix() -> None:
    points = RNG.normal(size=(6, 3))
    pose = Pose(position=(0.3, 0.1, -0.2), quaternion=tuple(QUATS[2]))
    homogeneous = np.c_[points, np.ones(len(points))] @ pose_matrix(pose).T
    moved = transform_points(points, pose.position, pose.quaternion)
    assert np.allclose(moved, homogeneous[:, :3])
    assert np.allclose(transform_points([tuple(p) for p in points], pose.position, pose.quaternion),
                       moved)


# --- rotation matrices ------------------------------------------------------------------


def test_rotation_angle_and_slerp() -> None:
    r0 = quat_to_matrix(QUATS[3])
    r1 = r0 @ axis_angle_matrix((1.0, 2.0, -1.0), 1.2)
    assert rotation_angle(r0, r1) == pytest.approx(1.2)
    assert np.allclose(slerp(r0, r1, 0.0), r0) and np.allclose(slerp(r0, r1, 1.0), r1)
    assert np.allclose(slerp(r0, r1, 0.25), r0 @ axis_angle_matrix((1.0, 2.0, -1.0), 0.3))
    # a half turn: the matrices leave the axis to a sign; slerp still ends at r1
    flipped = r0 @ axis_angle_matrix((0.0, 0.0, 1.0), math.pi)
    assert rotation_angle(r0, slerp(r0, flipped, 0.5)) == pytest.approx(math.pi / 2)
    assert np.allclose(slerp(r0, flipped, 1.0), flipped, atol=1e-12)


@pytest.mark.parametrize(("a", "b"), [((1, 0, 0), (0, 1, 0)), ((0.2, -0.3, 1.0), (1.0, 0.5, 0.1)),
                                      ((0, 0, 1), (0, 0, 1)), ((0, 0, 1), (0, 0, -1)),
                                      ((1, 0, 0), (-1, 0, 0))])
def test_rotation_between_is_the_smallest_turn(a, b) -> None:
    r = rotation_between(a, b)
    ua, ub = np.asarray(a, float) / np.linalg.norm(a), np.asarray(b, float) / np.linalg.norm(b)
    assert np.allclose(r @ ua, ub, atol=1e-12)
    assert np.allclose(r @ r.T, np.eye(3), atol=1e-12)
    angle = math.acos(float(np.clip(ua @ ub, -1.0, 1.0)))
    assert rotation_angle(np.eye(3), r) == pytest.approx(angle, abs=1e-7)


def test_opposite_directions_turn_about_a_cross_x() -> None:
    # the half turn the old helper chose: about a × x (a × y when a is along x)
    assert np.allclose(rotation_between((0, 0, 1), (0, 0, -1)), np.diag([-1.0, 1.0, -1.0]))
    assert np.allclose(rotation_between((1, 0, 0), (-1, 0, 0)), np.diag([-1.0, -1.0, 1.0]))


def test_point_axis_points_the_named_axis() -> None:
    r = quat_to_matrix(QUATS[4])
    for name, axis in AXES.items():
        turned = point_axis(r, name, (0.0, 0.0, -1.0))
        assert np.allclose(turned @ axis, [0.0, 0.0, -1.0], atol=1e-12)


# --- look-at ----------------------------------------------------------------------------


def test_look_at_a_sapien_camera() -> None:
    # a SAPIEN camera looks along its local +x, with +z up
    rot = quat_to_matrix(look_at_quat((1.0, 0.0, 1.0), (0.0, 0.0, 0.0)))
    assert np.allclose(rot[:, 0], np.array([-1.0, 0.0, -1.0]) / np.sqrt(2))
    assert rot[2, 2] > 0
    assert abs(rot[2, 1]) < 1e-12  # +y (left) stays horizontal
    # numbers the old helper (fsvla.embodiments.frames.look_at_quat) gave
    q = look_at_quat((-0.6, 0.3, 0.5), (-0.1, 0.0, 0.1))
    assert np.allclose(q, (0.9204918294, 0.0790454463, 0.2853791423, -0.2549614766), atol=1e-9)


def test_look_at_rejects_degenerate_views() -> None:
    with pytest.raises(ValueError, match="its own position"):
        look_at_quat((0.1, 0.2, 0.3), (0.1, 0.2, 0.3))
    with pytest.raises(ValueError, match="parallel to up"):
        look_at_quat((0.0, 0.0, 1.0), (0.0, 0.0, 0.0))
    rot = quat_to_matrix(look_along_quat((0.0, 0.0, -1.0), up=(1.0, 0.0, 0.0)))
    assert np.allclose(rot[:, 0], [0.0, 0.0, -1.0]) and rot[0, 2] > 0


def test_importing_the_module_does_not_import_scipy() -> None:
    code = "import sys, fsvla.compiler.pose; print('scipy' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"
