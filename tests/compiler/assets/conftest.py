"""Shared helpers for the asset-library tests."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh


def l_prism(thickness: float = 0.02, arm: float = 0.1, bar: float = 0.02) -> trimesh.Trimesh:
    """A watertight L-shaped prism: a clearly non-convex mesh."""
    outline = np.array(
        [[0, 0], [arm, 0], [arm, bar], [bar, bar], [bar, arm], [0, arm]], dtype=float
    )
    n = len(outline)
    vertices = np.vstack([np.c_[outline, np.zeros(n)], np.c_[outline, np.full(n, thickness)]])
    reflex = 3  # the inner corner sees every other vertex: fan-triangulate from it
    faces = []
    for i in range(n):
        j = (i + 1) % n
        if reflex not in (i, j):
            faces += [[reflex, j, i], [reflex + n, i + n, j + n]]
        faces += [[i, j, j + n], [i, j + n, i + n]]
    mesh = trimesh.Trimesh(vertices, faces, process=True)
    mesh.fix_normals()
    assert mesh.is_volume
    return mesh


@pytest.fixture
def l_mesh() -> trimesh.Trimesh:
    return l_prism()
