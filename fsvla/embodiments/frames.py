"""Small rigid-transform helpers in plain numpy (no simulator).

Quaternions are ``(w, x, y, z)``, the order SAPIEN uses. Rotation matrices act on
column vectors. The world frame is the table frame: origin at the centre of the
table top, +x forward (away from the main robot), +y left, +z up.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

Quat = tuple[float, float, float, float]
Vec3 = tuple[float, float, float]

AXES: dict[str, Vec3] = {
    "+x": (1.0, 0.0, 0.0),
    "-x": (-1.0, 0.0, 0.0),
    "+y": (0.0, 1.0, 0.0),
    "-y": (0.0, -1.0, 0.0),
    "+z": (0.0, 0.0, 1.0),
    "-z": (0.0, 0.0, -1.0),
}


def yaw_quat(yaw: float) -> Quat:
    """Quaternion (wxyz) of a rotation by ``yaw`` radians about +z."""
    return (float(np.cos(yaw / 2)), 0.0, 0.0, float(np.sin(yaw / 2)))


def quat_to_matrix(q: Quat | NDArray[np.floating]) -> NDArray[np.float64]:
    """3x3 rotation matrix of a (not necessarily unit) wxyz quaternion."""
    w, x, y, z = np.asarray(q, dtype=np.float64) / np.linalg.norm(q)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def matrix_to_quat(m: NDArray[np.floating]) -> Quat:
    """wxyz quaternion (w >= 0) of a 3x3 rotation matrix."""
    m = np.asarray(m, dtype=np.float64)
    trace = m[0, 0] + m[1, 1] + m[2, 2]
    if trace > 0:
        s = 2.0 * np.sqrt(trace + 1.0)
        q = (0.25 * s, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s)
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = 2.0 * np.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2])
        q = ((m[2, 1] - m[1, 2]) / s, 0.25 * s, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s)
    elif m[1, 1] > m[2, 2]:
        s = 2.0 * np.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2])
        q = ((m[0, 2] - m[2, 0]) / s, (m[0, 1] + m[1, 0]) / s, 0.25 * s, (m[1, 2] + m[2, 1]) / s)
    else:
        s = 2.0 * np.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1])
        q = ((m[1, 0] - m[0, 1]) / s, (m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, 0.25 * s)
    arr = np.asarray(q) / np.linalg.norm(q)
    if arr[0] < 0:
        arr = -arr
    return (float(arr[0]), float(arr[1]), float(arr[2]), float(arr[3]))


def look_at_quat(eye: Vec3, target: Vec3, up: Vec3 = (0.0, 0.0, 1.0)) -> Quat:
    """Orientation of a SAPIEN camera at ``eye`` looking at ``target``.

    A SAPIEN camera looks along its local +x, with +y to its left and +z up.
    Raises ``ValueError`` when the view direction is zero or parallel to ``up``.
    """
    forward = np.asarray(target, dtype=np.float64) - np.asarray(eye, dtype=np.float64)
    if np.linalg.norm(forward) < 1e-9:
        raise ValueError(f"camera looks at its own position {tuple(eye)}")
    forward /= np.linalg.norm(forward)
    left = np.cross(np.asarray(up, dtype=np.float64), forward)
    if np.linalg.norm(left) < 1e-6:
        raise ValueError(
            f"camera view direction {tuple(np.round(forward, 3))} is parallel to up {tuple(up)}; "
            "give another `up` vector"
        )
    left /= np.linalg.norm(left)
    cam_up = np.cross(forward, left)
    return matrix_to_quat(np.column_stack([forward, left, cam_up]))


def rotation_between(a: NDArray[np.floating], b: NDArray[np.floating]) -> NDArray[np.float64]:
    """Smallest rotation matrix taking direction ``a`` onto direction ``b``."""
    a = np.asarray(a, dtype=np.float64) / np.linalg.norm(a)
    b = np.asarray(b, dtype=np.float64) / np.linalg.norm(b)
    v = np.cross(a, b)
    c = float(a @ b)
    if np.linalg.norm(v) < 1e-9:
        if c > 0:
            return np.eye(3)
        perp = np.cross(a, [1.0, 0.0, 0.0])
        if np.linalg.norm(perp) < 1e-6:
            perp = np.cross(a, [0.0, 1.0, 0.0])
        perp /= np.linalg.norm(perp)
        return 2.0 * np.outer(perp, perp) - np.eye(3)
    k = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
    return np.eye(3) + k + k @ k / (1.0 + c)


def point_axis(rotation: NDArray[np.floating], axis: str, direction: Vec3) -> NDArray[np.float64]:
    """Rotate ``rotation`` minimally so that its local ``axis`` ("+z", ...) points along
    ``direction`` in the world; used for "gripper pointing down" targets."""
    rotation = np.asarray(rotation, dtype=np.float64)
    current = rotation @ np.asarray(AXES[axis])
    return rotation_between(current, np.asarray(direction)) @ rotation


__all__ = [
    "AXES", "Quat", "Vec3", "look_at_quat", "matrix_to_quat", "point_axis", "quat_to_matrix",
    "rotation_between", "yaw_quat",
]
