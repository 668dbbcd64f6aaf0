"""The policy interface, the built-in policies, and loading --policy values."""

from __future__ import annotations

import numpy as np
import pytest

from fsvla.policies import (
    ActionSchema,
    EpisodeInfo,
    HoldStillPolicy,
    ObservationSchema,
    Policy,
    PolicyLoadError,
    RandomPolicy,
    load_policy,
)
from fsvla.run.key import EpisodeKey


def _episode(seed: int = 0, mode: str = "joint_pos") -> EpisodeInfo:
    if mode == "joint_pos":
        labels = ("left.j1", "left.j2", "left.gripper", "right.j1", "right.gripper")
        low, high = (-1.0, -2.0, 0.0, -3.0, 0.0), (1.0, 2.0, 1.0, 3.0, 1.0)
    else:
        labels = tuple(f"arm.{c}" for c in ("x", "y", "z", "qw", "qx", "qy", "qz", "gripper"))
        low, high = (-2.0,) * 3 + (-1.01,) * 4 + (0.0,), (2.0,) * 3 + (1.01,) * 4 + (1.0,)
    arms = ("left", "right") if mode == "joint_pos" else ("arm",)
    key = EpisodeKey(scenario="s", suite="force", embodiment="dual_panda", seed=0)
    return EpisodeInfo(
        key=key, policy_seed=seed, instruction="do it", control_rate=20.0, max_steps=10,
        action=ActionSchema(control_mode=mode, labels=labels, low=low, high=high, arms=arms),
        observation=ObservationSchema(state_layout={}, cameras=()))


def test_random_policy_stays_in_bounds_and_is_seeded_per_episode() -> None:
    policy = RandomPolicy(seed=3)
    policy.reset(_episode(seed=1))
    first = [policy.act({}) for _ in range(50)]
    assert all(np.all(a >= -3.0) and np.all(a <= 3.0) for a in first)
    assert all(-1.0 <= a[0] <= 1.0 and 0.0 <= a[2] <= 1.0 for a in first)
    policy.reset(_episode(seed=1))
    assert np.array_equal(policy.act({}), first[0])
    policy.reset(_episode(seed=2))
    assert not np.array_equal(policy.act({}), first[0])


def test_hold_still_repeats_the_first_observed_configuration() -> None:
    policy = HoldStillPolicy()
    policy.reset(_episode())
    obs = {"agent": {"qpos": np.array([0.1, 0.2, 0.3]), "gripper": np.array([1.0, 0.5]),
                     "tcp_pose": np.zeros(14)}}
    assert policy.act(obs).tolist() == pytest.approx([0.1, 0.2, 1.0, 0.3, 0.5])
    obs["agent"]["qpos"] = np.array([9.0, 9.0, 9.0])
    assert policy.act(obs).tolist() == pytest.approx([0.1, 0.2, 1.0, 0.3, 0.5])


def test_hold_still_in_ee_pose_mode_holds_the_tcp_pose() -> None:
    policy = HoldStillPolicy()
    policy.reset(_episode(mode="ee_pose"))
    pose = np.array([0.1, 0.0, 0.2, 1.0, 0.0, 0.0, 0.0])
    obs = {"agent": {"qpos": np.zeros(7), "gripper": np.array([0.25]), "tcp_pose": pose}}
    assert policy.act(obs).tolist() == pytest.approx([*pose, 0.25])


def test_builtins_satisfy_the_protocol() -> None:
    assert isinstance(load_policy("random"), Policy)
    assert isinstance(load_policy("hold-still"), HoldStillPolicy)


def test_module_class_form(tmp_path) -> None:
    source = tmp_path / "mine.py"
    source.write_text("import numpy as np\n"
                      "class Zero:\n"
                      "    def reset(self, episode): self.n = len(episode.action.labels)\n"
                      "    def act(self, observation): return np.zeros(self.n)\n"
                      "class Broken:\n"
                      "    def __init__(self): raise RuntimeError('no weights')\n"
                      "class NotAPolicy:\n"
                      "    pass\n")
    policy = load_policy(f"{source}:Zero")
    policy.reset(_episode())
    assert policy.act({}).shape == (5,)
    with pytest.raises(PolicyLoadError, match="constructing Broken failed: RuntimeError: no weights"):
        load_policy(f"{source}:Broken")
    with pytest.raises(PolicyLoadError, match="lacks reset\\(episode\\) and act\\(observation\\)"):
        load_policy(f"{source}:NotAPolicy")
    with pytest.raises(PolicyLoadError, match="has no class or factory 'Missing'"):
        load_policy(f"{source}:Missing")


@pytest.mark.parametrize(
    ("spec", "message"),
    [
        ("randm", ("--policy 'randm': not a built-in policy, `module:Class`, ws://host:port "
                   "or lerobot:PATH; did you mean `random`?")),
        ("no_such_module_xyz:Policy", "--policy 'no_such_module_xyz:Policy': cannot import "
                                      "no_such_module_xyz: ModuleNotFoundError"),
        ("missing.py:Policy", "--policy 'missing.py:Policy': no such file missing.py"),
    ],
)
def test_bad_policy_values_are_explained(spec: str, message: str) -> None:
    with pytest.raises(PolicyLoadError) as caught:
        load_policy(spec)
    assert str(caught.value).startswith(message)
