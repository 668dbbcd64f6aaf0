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


def test_a_group_version_changes_when_and_only_when_one_of_its_frames_moves():
    geometry = SceneGeometry()
    for name, x in (("a", 0.0), ("b", 0.3), ("c", 0.6)):
        geometry.add(name, [SphereShape(radius=0.05)], _at(x))
    ab = frozenset({"a", "b"})
    geometry.set_poses({"a": _at(0.0)})
    before = geometry.version(ab)
    geometry.set_poses({"c": _at(0.7), "a": _at(POSE_TOLERANCE / 2)})  # c is not in the group; a jitters
    assert geometry.version(ab) == before
    geometry.set_poses({"b": _at(0.35)})
    moved = geometry.version(ab)
    assert moved > before
    geometry.set_poses({"a": _at(0.1), "b": _at(0.4)})
    assert geometry.version(ab) > moved
    assert geometry.version(frozenset({"nothing"})) == 0


def _pose(rng: np.random.Generator, centre: np.ndarray, turn: float) -> np.ndarray:
    """A random rotation of up to ``turn`` rad about a random axis, at ``centre``."""
    from scipy.spatial.transform import Rotation

    axis = rng.normal(size=3)
    m = np.eye(4)
    m[:3, :3] = Rotation.from_rotvec(axis / np.linalg.norm(axis) * rng.uniform(0, turn)).as_matrix()
    m[:3, 3] = centre
    return m


def test_a_piece_moves_no_farther_than_its_carried_bound():
    from fsvla.monitor.kernels import _moved

    rng = np.random.default_rng(3)
    for _ in range(200):
        then, now = _pose(rng, rng.uniform(-1, 1, 3), np.pi), _pose(rng, rng.uniform(-1, 1, 3), np.pi)
        centre, radius = rng.uniform(-0.2, 0.2, 3), rng.uniform(0.0, 0.1)
        offsets = rng.normal(size=(50, 3))
        offsets *= radius * rng.uniform(0, 1, (50, 1)) / np.linalg.norm(offsets, axis=1, keepdims=True)
        points = centre + offsets  # within radius of the centre, in the frame
        moved = np.linalg.norm(points @ now[:3, :3].T + now[:3, 3] - points @ then[:3, :3].T - then[:3, 3], axis=1)
        assert moved.max() <= _moved.py_func(now, then, centre, radius) + 1e-12
    assert _moved.py_func(now, now, centre, radius) == 0.0


def test_a_piece_is_placed_where_its_frame_puts_it():
    from fsvla.monitor.kernels import place_piece

    rng = np.random.default_rng(4)
    poses = np.stack([_pose(rng, rng.uniform(-1, 1, 3), np.pi) for _ in range(3)])
    local = _pose(rng, rng.uniform(-0.1, 0.1, 3), np.pi)
    rotation, translation = np.zeros((3, 3)), np.zeros(3)
    place_piece(poses, 2, local, rotation, translation)
    world = poses[2] @ local
    np.testing.assert_allclose(rotation, world[:3, :3], rtol=0, atol=1e-15)
    np.testing.assert_allclose(translation, world[:3, 3], rtol=0, atol=1e-15)


@pytest.mark.parametrize("seed", range(3))
def test_carried_bounds_keep_a_moving_minimum_exact(seed: int, monkeypatch):
    """Box clouds drift, turn and pass through each other: every step's minimum equals brute
    force, and the bounds carried from the step before spare most exact queries."""
    import fsvla.monitor.geometry as module

    calls = []
    exact = module.signed_distance
    monkeypatch.setattr(module, "signed_distance", lambda a, b: calls.append(1) or exact(a, b))
    rng = np.random.default_rng(seed)
    core = BoxShape(half_size=(0.05, 0.05, 0.05))  # at both origins: the clouds pass through each other
    sa, sb = [core, *_boxes(rng, 10)], [core, *_boxes(rng, 8)]
    geometry = SceneGeometry()
    geometry.add("a", sa)
    geometry.add("b", sb, _at(0.6))
    steps, fresh, deepest = 60, 0, MAX_DISTANCE
    for t in range(steps):
        pose = _pose(rng, np.array([0.6 - 0.012 * t, 0.0, 0.0]), 0.02)
        geometry.set_poses({"b": pose})
        brute = min_distance(pieces_of("a", sa), pieces_of("b", sb, pose))
        fresh += len(sa) * len(sb)
        assert geometry.distance(A, B) == pytest.approx(brute, abs=1e-9), t
        deepest = min(deepest, brute)
        lower = geometry.distance(A, B, exact_below=brute - 0.05)
        assert lower >= brute - 0.05
    assert deepest < 0.0  # they passed through each other
    assert len(calls) < fresh / 10


def test_group_bounds_hold_every_piece_of_every_frame():
    rng = np.random.default_rng(5)
    geometry = SceneGeometry()
    shapes = {f: _boxes(rng, 4) for f in ("a", "b", "c")}
    for f, s in shapes.items():
        geometry.add(f, s)
    poses = {f: _pose(rng, rng.uniform(-1, 1, 3), np.pi) for f in shapes}
    geometry.set_poses(poses)
    for group in (frozenset({"a"}), frozenset({"a", "c"}), frozenset({"a", "b", "c", "nothing"})):
        corners = np.concatenate([
            (np.array(np.meshgrid(*[(-1, 1)] * 3)).reshape(3, -1).T * box.half_size + box.pose.position)
            @ poses[f][:3, :3].T + poses[f][:3, 3] for f in group if f in shapes for box in shapes[f]])
        lo, hi = geometry.bounds(group)
        np.testing.assert_allclose(lo, corners.min(axis=0), atol=1e-12)
        np.testing.assert_allclose(hi, corners.max(axis=0), atol=1e-12)
    assert geometry.bounds(frozenset({"nothing"})) is None
