"""Rotations and rigid poses: the one module that converts between quaternions, rotation
matrices, axis-angles, yaws and frames, built on ``scipy.spatial.transform.Rotation``.

Conventions, stated here once for all of fsvla:

- **Quaternions are (w, x, y, z)**, scalar first: the order SAPIEN uses and the order scene
  and monitor specs store. scipy's ``Rotation`` takes and gives (x, y, z, w); the two
  private helpers ``_rotation`` and ``_wxyz`` are the only places that reorder. A
  quaternion this module derives from a matrix has w >= 0; one built from an angle (yaw,
  axis-angle) or a product keeps the sign its formula gives, as the specs always had.
- Rotation matrices act on column vectors: a point ``p`` of a frame at (R, t) is
  ``R @ p + t`` in the parent frame. A pose matrix is the 4 × 4 homogeneous ``[R t; 0 1]``.
- Angles are in radians. The world frame is the table frame: origin at the centre of the
  table top, +x forward (away from the main robot), +y left, +z up; a yaw turns about +z,
  counter-clockwise seen from above.

It lives in the compiler (import name ``fsvla.compiler.pose``) because the compiler is
the lowest layer that both the compiler (assets, placement, layout feasibility) and the
runtime (embodiments, the SAPIEN scene, experts, monitor, variations) import, and it
imports no simulator. scipy (the ``compiler`` extra) is imported on first use, so
importing this module costs numpy alone: ``fsvla check`` never loads scipy.

Rotations about +z alone (:func:`yaw_quat`, :func:`quat_yaw`, :func:`rotate_xy`,
:func:`yaw_matrix`) are closed-form cosines and sines: the layout sampler calls them
thousands of times a variant, and one scipy ``Rotation`` round trip costs ~20 µs. The
tests hold them to ``Rotation``'s answers.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from typing import TYPE_CHECKING, Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

if TYPE_CHECKING:
    from scipy.spatial.transform import Rotation

Vec2 = tuple[float, float]
Vec3 = tuple[float, float, float]
Quat = tuple[float, float, float, float]  # (w, x, y, z)
Matrix = NDArray[np.float64]

IDENTITY: Quat = (1.0, 0.0, 0.0, 0.0)

#: The unit axes by the names specs use for them ("+z": a gripper's approach axis, ...).
AXES: dict[str, Vec3] = {
    "+x": (1.0, 0.0, 0.0),
    "-x": (-1.0, 0.0, 0.0),
    "+y": (0.0, 1.0, 0.0),
    "-y": (0.0, -1.0, 0.0),
    "+z": (0.0, 0.0, 1.0),
    "-z": (0.0, 0.0, -1.0),
}


class PoseLike(Protocol):
    """Anything with a position and a (w, x, y, z) quaternion, such as a spec's ``Pose``."""

    @property
    def position(self) -> Sequence[float]: ...

    @property
    def quaternion(self) -> Sequence[float]: ...


# --- the scipy boundary -----------------------------------------------------------------


def _rotation(q: ArrayLike) -> Rotation:
    """scipy's Rotation of one or more (w, x, y, z) quaternions (normalised by scipy)."""
    from scipy.spatial.transform import Rotation

    return Rotation.from_quat(np.asarray(q, dtype=np.float64)[..., [1, 2, 3, 0]])


def _wxyz(rotation: Rotation, *, canonical: bool = False) -> Quat:
    """The (w, x, y, z) quaternion of one scipy Rotation; with ``canonical``, w >= 0."""
    x, y, z, w = (float(v) for v in rotation.as_quat())
    if canonical and w < 0:
        x, y, z, w = -x, -y, -z, -w
    return (w, x, y, z)


# --- conversions ------------------------------------------------------------------------


def quat_to_matrix(q: ArrayLike) -> Matrix:
    """The 3 × 3 rotation matrix of a (not necessarily unit) quaternion; an (N, 4) array of
    quaternions gives (N, 3, 3)."""
    return _rotation(q).as_matrix()


def matrix_to_quat(m: ArrayLike) -> Quat:
    """The quaternion (w >= 0) of a 3 × 3 rotation matrix."""
    from scipy.spatial.transform import Rotation

    return _wxyz(Rotation.from_matrix(np.asarray(m, dtype=np.float64)), canonical=True)


def quat_mul(a: Sequence[float], b: Sequence[float]) -> Quat:
    """The product ``a ⊗ b``: the rotation ``b`` first, then ``a`` (matrix ``A @ B``)."""
    return _wxyz(_rotation(a) * _rotation(b))


def axis_angle_quat(axis: ArrayLike, angle: float) -> Quat:
    """The quaternion turning by ``angle`` about ``axis`` (any length but zero)."""
    from scipy.spatial.transform import Rotation

    direction = np.asarray(axis, dtype=np.float64)
    return _wxyz(Rotation.from_rotvec(direction / np.linalg.norm(direction) * angle))


def axis_angle_matrix(axis: ArrayLike, angle: float) -> Matrix:
    """The rotation matrix turning by ``angle`` about ``axis`` (any length but zero)."""
    from scipy.spatial.transform import Rotation

    direction = np.asarray(axis, dtype=np.float64)
    return Rotation.from_rotvec(direction / np.linalg.norm(direction) * angle).as_matrix()


def rpy_quat(rpy: Sequence[float]) -> Quat:
    """The quaternion (w >= 0) of URDF's roll, pitch, yaw: turns about the fixed x, y, z
    axes in that order (``Rz(yaw) @ Ry(pitch) @ Rx(roll)``)."""
    from scipy.spatial.transform import Rotation

    return _wxyz(Rotation.from_euler("xyz", np.asarray(rpy, dtype=np.float64)), canonical=True)


# --- yaw: rotations about +z, closed form -----------------------------------------------


def yaw_quat(yaw: float) -> Quat:
    """The quaternion of a turn by ``yaw`` about +z."""
    return (math.cos(yaw / 2.0), 0.0, 0.0, math.sin(yaw / 2.0))


def quat_yaw(q: Sequence[float]) -> float:
    """The heading of a quaternion: the yaw of its x-axis (exact for turns about z only)."""
    w, x, y, z = (float(v) for v in q)
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def rotate_xy(xy: Sequence[float], yaw: float) -> Vec2:
    """The point ``xy`` turned by ``yaw`` about the origin."""
    c, s = math.cos(yaw), math.sin(yaw)
    x, y = float(xy[0]), float(xy[1])
    return (c * x - s * y, s * x + c * y)


def yaw_matrix(position: Sequence[float], yaw: float) -> Matrix:
    """The pose matrix of a frame at ``position`` turned by ``yaw`` about +z."""
    c, s = math.cos(yaw), math.sin(yaw)
    m = np.eye(4)
    m[0, 0], m[0, 1], m[1, 0], m[1, 1] = c, -s, s, c
    m[:3, 3] = position
    return m


# --- poses ------------------------------------------------------------------------------


def pose_matrix(pose: PoseLike) -> Matrix:
    """The 4 × 4 homogeneous matrix of ``pose``."""
    m = np.eye(4)
    m[:3, :3] = quat_to_matrix(pose.quaternion)
    m[:3, 3] = pose.position
    return m


def transform_points(points: Iterable[Sequence[float]] | ArrayLike, position: Sequence[float],
                     quaternion: Sequence[float]) -> Matrix:
    """``points`` (N × 3) of a frame at ``position`` and ``quaternion``, in the parent frame."""
    p = np.asarray(points if isinstance(points, np.ndarray) else list(points), dtype=np.float64)
    return p @ quat_to_matrix(quaternion).T + np.asarray(position, dtype=np.float64)


# --- rotation matrices ------------------------------------------------------------------


def rotation_angle(r0: ArrayLike, r1: ArrayLike) -> float:
    """The angle of the rotation taking ``r0`` to ``r1`` (both 3 × 3 matrices), in [0, π]."""
    rel = np.asarray(r0, dtype=np.float64).T @ np.asarray(r1, dtype=np.float64)
    return float(np.arccos(np.clip((np.trace(rel) - 1.0) / 2.0, -1.0, 1.0)))


def slerp(r0: Matrix, r1: Matrix, s: float) -> Matrix:
    """The rotation a fraction ``s`` of the way from ``r0`` to ``r1``, about one axis. A half
    turn, whose axis the matrices leave to a sign, turns about the axis ``eigh`` gives."""
    rel = r0.T @ r1
    angle = rotation_angle(r0, r1)
    if angle < 1e-9:
        return r1.copy()
    axis = np.array([rel[2, 1] - rel[1, 2], rel[0, 2] - rel[2, 0], rel[1, 0] - rel[0, 1]])
    if np.linalg.norm(axis) < 1e-9:  # a half turn: its axis is rel + relᵀ's top eigenvector
        w, v = np.linalg.eigh(rel + rel.T)
        axis = v[:, np.argmax(w)]
    return r0 @ axis_angle_matrix(axis, s * angle)


def rotation_between(a: ArrayLike, b: ArrayLike) -> Matrix:
    """The smallest rotation matrix taking direction ``a`` onto direction ``b``; opposite
    directions turn by a half turn about ``a × x`` (``a × y`` when ``a`` is along x)."""
    a = np.asarray(a, dtype=np.float64) / np.linalg.norm(a)
    b = np.asarray(b, dtype=np.float64) / np.linalg.norm(b)
    v = np.cross(a, b)
    sine, cosine = float(np.linalg.norm(v)), float(a @ b)
    if sine < 1e-9:
        if cosine > 0:
            return np.eye(3)
        v = np.cross(a, [1.0, 0.0, 0.0])
        if np.linalg.norm(v) < 1e-6:
            v = np.cross(a, [0.0, 1.0, 0.0])
    return axis_angle_matrix(v, math.atan2(sine, cosine))


def point_axis(rotation: ArrayLike, axis: str, direction: Sequence[float]) -> Matrix:
    """``rotation`` turned minimally so that its local ``axis`` ("+z", ...) points along
    ``direction`` in the world; used for "gripper pointing down" targets."""
    rotation = np.asarray(rotation, dtype=np.float64)
    current = rotation @ np.asarray(AXES[axis])
    return rotation_between(current, np.asarray(direction)) @ rotation


def look_along_quat(forward: ArrayLike, up: Sequence[float] = (0.0, 0.0, 1.0)) -> Quat:
    """The frame whose +x points along ``forward`` and whose +z is as near ``up`` as it can
    be (+y to its left): a SAPIEN camera's or light's orientation. Raises ``ValueError``
    when ``forward`` is parallel to ``up``."""
    x = np.asarray(forward, dtype=np.float64)
    x = x / np.linalg.norm(x)
    y = np.cross(np.asarray(up, dtype=np.float64), x)
    if np.linalg.norm(y) < 1e-6:
        raise ValueError(
            f"view direction {tuple(np.round(x, 3))} is parallel to up {tuple(up)}; "
            "give another `up` vector"
        )
    y /= np.linalg.norm(y)
    return matrix_to_quat(np.column_stack([x, y, np.cross(x, y)]))


def look_at_quat(eye: Sequence[float], target: Sequence[float],
                 up: Sequence[float] = (0.0, 0.0, 1.0)) -> Quat:
    """The orientation of a SAPIEN camera at ``eye`` looking at ``target`` (it looks along
    its local +x, +y to its left, +z up). Raises ``ValueError`` when ``eye`` is
    ``target`` or the view is parallel to ``up``."""
    forward = np.asarray(target, dtype=np.float64) - np.asarray(eye, dtype=np.float64)
    if np.linalg.norm(forward) < 1e-9:
        raise ValueError(f"camera looks at its own position {tuple(eye)}")
    return look_along_quat(forward, up)


__all__ = [
    "AXES", "IDENTITY", "Matrix", "PoseLike", "Quat", "Vec2", "Vec3", "axis_angle_matrix",
    "axis_angle_quat", "look_along_quat", "look_at_quat", "matrix_to_quat", "point_axis",
    "pose_matrix", "quat_mul", "quat_to_matrix", "quat_yaw", "rotate_xy", "rotation_angle",
    "rotation_between", "rpy_quat", "slerp", "transform_points", "yaw_matrix", "yaw_quat",
]
