"""WorldState's contact queries, and PoseMap, against plain definitions."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from fsvla.monitor.state import PoseMap, WorldState, pair_key

FRAMES = [f"f{i}" for i in range(8)]


def _brute_max_force(state: WorldState, a: frozenset[str], b: frozenset[str]) -> float:
    return max((v for (x, y), v in state.contact_force.items()
                if (x in a and y in b) or (y in a and x in b)), default=0.0)


@pytest.mark.parametrize("seed", range(20))
def test_contact_queries_agree_with_their_definitions(seed: int):
    """Small groups look pairs up, large ones go through the contacts: the same answers."""
    rng = np.random.default_rng(seed)
    pairs = [p for p in itertools.combinations(FRAMES, 2) if rng.random() < 0.4]
    last = [p for p in itertools.permutations(FRAMES, 2) if rng.random() < 0.1]
    state = WorldState(step=1, time=0.05, poses={},
                       contact_force={pair_key(*p): float(rng.uniform(0.0, 5.0)) for p in pairs},
                       last_contacts={p: rng.normal(size=3) for p in last})
    for _ in range(30):
        a = frozenset(f for f in FRAMES if rng.random() < rng.uniform(0.1, 0.6))
        b = frozenset(f for f in FRAMES if rng.random() < rng.uniform(0.1, 0.6))
        assert state.max_force(a, b) == _brute_max_force(state, a, b)
        touching = _brute_max_force(state, a, b) > 0.0 or any(x in a and y in b for x, y in last)
        assert state.touching(a, b) == touching


def test_pose_map_is_a_read_only_mapping_of_views():
    stack = np.arange(3 * 16, dtype=np.float32).reshape(3, 4, 4)
    poses = PoseMap(("a", "b", "c"), stack)
    assert list(poses) == ["a", "b", "c"] and len(poses) == 3
    assert "b" in poses and "d" not in poses
    assert poses.get("d") is None
    np.testing.assert_array_equal(poses["c"], stack[2])
    assert np.shares_memory(poses.get("a"), stack)
    assert dict(poses.items()).keys() == {"a", "b", "c"}
    with pytest.raises(KeyError):
        poses["d"]
