"""FCL geometry from compiler shapes: distances match the closed-form answers."""

from __future__ import annotations

import numpy as np
import pytest
from fsvla.compiler.assets.model import (
    BoxShape,
    CapsuleShape,
    ConvexMeshShape,
    CylinderShape,
    InlineMesh,
    Pose,
    SphereShape,
)
from fsvla.compiler.collision import min_distance, pieces_of
from fsvla.compiler.pose import pose_matrix


def _at(x: float, y: float = 0.0, z: float = 0.0) -> np.ndarray:
    return pose_matrix(Pose(position=(x, y, z)))


@pytest.mark.parametrize(
    ("shape", "extent"),
    [
        (BoxShape(half_size=(0.05, 0.1, 0.1)), 0.05),
        (CylinderShape(radius=0.04, half_length=0.2), 0.04),
        (CapsuleShape(radius=0.03, half_length=0.2), 0.03),
        (SphereShape(radius=0.02), 0.02),
    ],
)
def test_distance_to_a_sphere_along_x(shape, extent: float) -> None:
    a = pieces_of("a", [shape])
    b = pieces_of("b", [SphereShape(radius=0.01)], _at(0.5))
    assert min_distance(a, b) == pytest.approx(0.5 - extent - 0.01, abs=1e-6)


def test_overlap_is_negative_penetration_depth() -> None:
    a = pieces_of("a", [BoxShape(half_size=(0.05, 0.05, 0.05))])
    b = pieces_of("b", [CylinderShape(radius=0.05, half_length=0.1)], _at(0.06))
    assert min_distance(a, b) == pytest.approx(-0.04, abs=1e-4)


def test_convex_piece_is_the_hull_of_its_vertices() -> None:
    cube = [(sx * 0.05, sy * 0.05, sz * 0.05) for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]
    cube.append((0.0, 0.0, 0.0))  # an interior point changes nothing
    shape = ConvexMeshShape(mesh=InlineMesh(vertices=cube, faces=[(0, 1, 2)]))
    a = pieces_of("a", [shape])
    b = pieces_of("b", [SphereShape(radius=0.01)], _at(0.0, 0.3))
    assert min_distance(a, b) == pytest.approx(0.3 - 0.05 - 0.01, abs=1e-6)


def test_shape_pose_and_owner_pose_compose() -> None:
    shape = SphereShape(radius=0.01, pose=Pose(position=(0.1, 0.0, 0.0)))
    a = pieces_of("a", [shape], _at(0.2))
    b = pieces_of("b", [SphereShape(radius=0.01)], _at(0.6))
    assert min_distance(a, b) == pytest.approx(0.6 - 0.3 - 0.02, abs=1e-6)
    a[0].place(_at(0.0))
    assert min_distance(a, b) == pytest.approx(0.6 - 0.1 - 0.02, abs=1e-6)
