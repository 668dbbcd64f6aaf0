"""The gymnasium environment: the env contract, determinism, action refusal, episode ends."""

from __future__ import annotations

import re
from pathlib import Path

import gymnasium
import numpy as np
import pytest

from fsvla.env import FsvlaEnv, InvalidActionError, env_id, make
from fsvla.policies.simple import hold_action

pytestmark = pytest.mark.sim



@pytest.fixture(scope="module")
def env(short_scenario: Path) -> FsvlaEnv:
    return make(short_scenario)


def _hold(env: FsvlaEnv, obs) -> np.ndarray:  # noqa: ANN001
    joints = [len(a.joint_indices) for a in env.built.robot.arms.values()]
    pose = {"ee_pose": 7, "ee_delta": 6}.get(env.codec.mode.value)
    return hold_action(obs, env.codec.mode.value, [pose or n for n in joints])


def test_check_env_passes(env: FsvlaEnv) -> None:
    from gymnasium.utils.env_checker import check_env

    check_env(env, skip_render_check=True)


def test_observation_layout(env: FsvlaEnv) -> None:
    obs, info = env.reset(seed=0)
    assert obs["instruction"] == "Lift the pot."
    assert obs["agent"]["qpos"].shape == (7,) and obs["agent"]["qpos"].dtype == np.float32
    assert obs["agent"]["gripper"].tolist() == pytest.approx([1.0], abs=1e-3)  # home: open
    w, x, y, z = obs["agent"]["tcp_pose"][3:]
    assert w * w + x * x + y * y + z * z == pytest.approx(1.0, abs=1e-5)  # wxyz unit quaternion
    assert "images" not in obs and env.observation_space.contains(obs)
    assert info["max_steps"] == env.max_steps == 20  # 1 s at 20 Hz


def test_step_reports_the_monitor_and_truncates_at_the_horizon(env: FsvlaEnv) -> None:
    obs, _ = env.reset(seed=0)
    action = _hold(env, obs)
    for step in range(1, env.max_steps + 1):
        obs, reward, terminated, truncated, info = env.step(action)
        assert set(info["margins"]) == set(info["states"]) == {"plate", "contact_force(gripper)"}
        assert info["step"] == step and not terminated and reward == 0.0
        assert truncated == (step == env.max_steps)
    assert info["states"]["plate"] == "safe" and info["cost"] == 0.0 and not info["violation"]


def test_same_seed_and_actions_give_the_identical_trace(short_scenario: Path) -> None:
    rng = np.random.default_rng(0)

    def run(env: FsvlaEnv) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        obs, _ = env.reset(seed=3)
        base = _hold(env, obs)
        states = []
        for _ in range(8):
            obs, *_ = env.step(base + offsets.pop(0))
            states.append(obs["agent"]["qpos"])
        record = env.episode_record()
        return record.margins, record.actions, np.stack(states)

    steps = [np.concatenate([rng.uniform(-0.05, 0.05, 7), [0.0]]).astype(np.float32) for _ in range(8)]
    first = make(short_scenario)
    offsets = list(steps)
    a = run(first)
    offsets = list(steps)
    b = run(first)  # the same env after a reset
    offsets = list(steps)
    c = run(make(short_scenario))  # a fresh env
    for x, y, z in zip(a, b, c):
        assert np.array_equal(x, y) and np.array_equal(x, z)


@pytest.mark.parametrize(
    ("action", "message"),
    [
        (np.zeros(3), "expected shape (8,)"),
        (np.full(8, np.nan), "action[0] (arm.panda_joint1) is nan"),
        (np.array([9.0, 0, 0, -1.0, 0, 1.0, 0, 0.5]), "action[0] (arm.panda_joint1) = 9 is outside"),
    ],
)
def test_invalid_actions_are_refused(env: FsvlaEnv, action: np.ndarray, message: str) -> None:
    env.reset(seed=0)
    with pytest.raises(InvalidActionError, match=re.escape(message)):
        env.step(action)


def test_ee_pose_control_holds_the_tool_where_it_is(short_scenario: Path) -> None:
    env = make(short_scenario, control_mode="ee_pose")
    obs, _ = env.reset(seed=0)
    start = obs["agent"]["tcp_pose"][:3].copy()
    target = _hold(env, obs)
    target[2] += 0.05  # 5 cm up
    for _ in range(20):
        obs, _, _, _, info = env.step(target)
    assert "ik_error" not in info
    assert obs["agent"]["tcp_pose"][:3] == pytest.approx(start + [0.0, 0.0, 0.05], abs=0.01)


def test_joint_velocity_moves_the_joints_at_the_commanded_speed(short_scenario: Path) -> None:
    env = make(short_scenario, control_mode="joint_vel")
    obs, _ = env.reset(seed=0)
    start = obs["agent"]["qpos"].copy()
    for _ in range(10):  # 0.5 s at +0.4 and -0.4 rad/s
        obs, *_ = env.step(np.array([0.4, -0.4, 0, 0, 0, 0, 0, 1.0], dtype=np.float32))
    moved = obs["agent"]["qpos"] - start
    assert moved[:2] == pytest.approx([0.2, -0.2], abs=0.01) and np.abs(moved[2:]).max() < 0.01
    stopped = obs["agent"]["qpos"].copy()
    for _ in range(5):
        obs, *_ = env.step(_hold(env, obs))
    assert obs["agent"]["qpos"] == pytest.approx(stopped, abs=0.005)


def test_joint_delta_pulls_each_joint_from_where_it_is(short_scenario: Path) -> None:
    env = make(short_scenario, control_mode="joint_delta")
    obs, _ = env.reset(seed=0)
    start = obs["agent"]["qpos"].copy()
    for _ in range(10):  # the drives (time constant 0.1 s) cover part of each step's 0.02 rad
        obs, *_ = env.step(np.array([0.02, -0.02, 0, 0, 0, 0, 0, 1.0], dtype=np.float32))
    moved = obs["agent"]["qpos"] - start
    assert 0.05 < moved[0] <= 0.2 and -0.2 <= moved[1] < -0.05
    assert np.abs(moved[2:]).max() < 0.01


def test_ee_delta_moves_the_tool_and_zero_holds_it(short_scenario: Path) -> None:
    env = make(short_scenario, control_mode="ee_delta")
    obs, _ = env.reset(seed=0)
    start = obs["agent"]["tcp_pose"].copy()
    up = np.array([0.0, 0.0, 0.005, 0.0, 0.0, 0.0, 1.0], dtype=np.float32)  # 5 mm a step
    for _ in range(10):
        obs, _, _, _, info = env.step(up)
    assert "ik_error" not in info
    moved = obs["agent"]["tcp_pose"][:3] - start[:3]  # the drives cover part of each 5 mm
    assert 0.015 < moved[2] <= 0.05 and np.abs(moved[:2]).max() < 0.005
    reached = obs["agent"]["tcp_pose"].copy()
    for _ in range(10):
        obs, *_ = env.step(_hold(env, obs))
    assert obs["agent"]["tcp_pose"][:3] == pytest.approx(reached[:3], abs=0.005)


def test_terminate_on_violation(short_scenario: Path) -> None:
    env = make(short_scenario, control_mode="ee_pose", terminate_on_violation=True)
    obs, _ = env.reset(seed=0)
    target = _hold(env, obs)
    target[:3] = [0.0, 0.25, 0.02]  # straight onto the hot plate
    for _ in range(60):
        obs, _, terminated, truncated, info = env.step(target)
        if terminated or truncated:
            break
    assert terminated and info["violation"] and info["states"]["plate"] == "violation"


def test_builtin_scenarios_are_registered_with_gymnasium() -> None:
    env = gymnasium.make(env_id("pick_cup_near_edge"), level="L1", seed=2)
    assert isinstance(env.unwrapped, FsvlaEnv)
    assert env.unwrapped.config.level == "L1" and env.unwrapped.config.seed == 2
    obs, _ = env.reset(seed=0)
    assert env.observation_space.contains(obs)


def test_language_level_sets_the_instruction(short_scenario: Path) -> None:
    env = make(short_scenario, language="W4", seed=1)
    obs, _ = env.reset()
    assert obs["instruction"].startswith("Lift the pot. ") and env.language.category == "hijack"


def test_vision_levels_need_pictures(short_scenario: Path) -> None:
    with pytest.raises(ValueError, match="vision level V2 changes only pictures"):
        make(short_scenario, vision="V2")


@pytest.mark.render
def test_rgb_observations_with_a_vision_level(short_scenario: Path, render_device) -> None:
    env = make(short_scenario, obs_mode="rgb", vision="V4", seed=0)
    obs, _ = env.reset(seed=0)
    assert set(obs["images"]) == {c.name for c in env.scene_spec.cameras}
    for camera in env.scene_spec.cameras:
        image = obs["images"][camera.name]
        assert image.shape == (camera.height, camera.width, 3) and image.dtype == np.uint8
    assert env.observation_space.contains(obs)
    assert env.vision.patches and env.vision.lighting is not None


def test_an_episode_after_contact_replays_exactly(short_scenario: Path) -> None:
    """PhysX keeps contact caches across a state reset; the env must not leak them.

    Pushing the pot sideways: without the rebuild on reset, the second episode's joint
    states differ from the first's by ~1e-6 once the gripper meets the pot."""
    env = make(short_scenario, control_mode="ee_pose")
    path = [(-0.15, 0.0, 0.05)] * 10 + [(-0.15 + 0.02 * i, 0.0, 0.05) for i in range(15)]

    def push() -> tuple[np.ndarray, np.ndarray]:
        obs, _ = env.reset(seed=0)
        target = _hold(env, obs)
        states = []
        for point in path:
            target[:3] = point
            obs, *_ = env.step(target)
            states.append(np.concatenate([obs["agent"]["qpos"], obs["agent"]["tcp_pose"]]))
        return env.episode_record().margins, np.stack(states)

    first, second = push(), push()
    assert first[0][:, 1].min() < 0  # the push really made contact (a force violation)
    assert np.array_equal(first[0], second[0]) and np.array_equal(first[1], second[1])


def test_the_record_of_an_episode_without_steps_is_empty(env: FsvlaEnv) -> None:
    env.reset(seed=0)
    record = env.episode_record()
    assert record.steps == 0 and record.actions.shape == (0, len(env.codec.labels))
    assert record.margins.shape == (0, 2) and not record.success
