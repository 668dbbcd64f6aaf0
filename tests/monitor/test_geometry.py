"""The broad phase: exact minima, lower bounds beyond exact_below, tolerance and memo."""

from __future__ import annotations

import numpy as np
import pytest
from fsvla.compiler.assets.model import BoxShape, Pose, SphereShape
from fsvla.compiler.collision import min_distance, pieces_of

from fsvla.monitor.geometry import MAX_DISTANCE, POSE_TOLERANCE, SceneGeometry

A, B = frozenset({"a"}), frozenset({"b"})


def _boxes(rng: np.random.Generator, n: int) -> list[BoxShape]:
    return [BoxShape(pose=Pose(position=tuple(rng.uniform(-0.2, 0.2, 3))),
                     half_size=tuple(rng.uniform(0.005, 0.05, 3))) for _ in range(n)]


def _at(x: float) -> np.ndarray:
    m = np.eye(4)
    m[0, 3] = x
    return m


@pytest.mark.parametrize("seed", range(5))
def test_broad_phase_minimum_is_exact(seed: int):
    rng = np.random.default_rng(seed)
    sa, sb = _boxes(rng, 12), _boxes(rng, 9)
    geometry = SceneGeometry()
    geometry.add("a", sa)
    geometry.add("b", sb, _at(0.6))
    brute = min_distance(pieces_of("a", sa), pieces_of("b", sb, _at(0.6)))
    assert geometry.distance(A, B) == pytest.approx(brute, abs=1e-12)
    lower = geometry.distance(A, B, exact_below=brute / 2)  # the answer lies beyond: a bound
    assert brute / 2 <= lower <= brute + 1e-12


def test_empty_groups_and_moves():
    geometry = SceneGeometry()
    geometry.add("a", [SphereShape(radius=0.05)])
    geometry.add("b", [SphereShape(radius=0.05)], _at(0.3))
    assert geometry.distance(A, frozenset({"nothing"})) == MAX_DISTANCE
    assert geometry.distance(A, B) == pytest.approx(0.2)
    geometry.set_poses({"b": _at(0.3 + POSE_TOLERANCE / 2)})  # jitter: not re-posed
    assert geometry.distance(A, B) == pytest.approx(0.2)
    geometry.set_poses({"b": _at(0.25)})
    assert geometry.distance(A, B) == pytest.approx(0.15)
    geometry.set_poses({"b": _at(0.05)})  # overlapping: the penetration depth
    assert geometry.distance(A, B) == pytest.approx(-0.05, abs=1e-3)
