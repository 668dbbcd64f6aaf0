"""``--policy lerobot:PATH``: a LeRobot checkpoint folder evaluated by ``fsvla run``.

The feature mapping is checked here with fsvla's own types; the whole path (a tiny,
randomly initialised ACT saved by LeRobot, then ``fsvla run`` with rgb observations)
runs in an interpreter that has LeRobot and fsvla (tests/collect/lerobot_loader.py
finds it: skipped without one, a failure under CI with ``FSVLA_REQUIRE_LEROBOT=1``).
"""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

from fsvla.policies import PolicyLoadError, load_policy
from fsvla.policies.base import ActionSchema, CameraSchema, EpisodeInfo, ObservationSchema
from fsvla.policies.lerobot import (
    FeatureMap,
    LeRobotMismatch,
    check_inputs,
    map_features,
    observation_arrays,
)
from fsvla.run.key import EpisodeKey

TINY_ACT = Path(__file__).with_name("tiny_act.py")
JOINTS = tuple(f"arm.j{i}" for i in range(7))


def _episode(rgb: bool = True) -> EpisodeInfo:
    labels = (*JOINTS, "arm.gripper")
    cameras = (CameraSchema(name="front", height=240, width=320, mount="world"),
               CameraSchema(name="wrist", height=240, width=320, mount="arm"))
    return EpisodeInfo(
        key=EpisodeKey(scenario="s", suite="force", embodiment="panda", seed=0),
        policy_seed=0, instruction="lift the pot", control_rate=20.0, max_steps=20,
        action=ActionSchema(control_mode="joint_pos", labels=labels, low=(-3.0,) * 8,
                            high=(3.0,) * 8, arms=("arm",)),
        observation=ObservationSchema(
            state_layout={"qpos": JOINTS, "gripper": ("arm.gripper",),
                          "tcp_pose": tuple(f"arm.{c}" for c in "xyz") + ("arm.qw", "arm.qx",
                                                                          "arm.qy", "arm.qz")},
            cameras=cameras if rgb else ()))


# ---------------------------------------------------------------- the feature mapping
def test_declared_features_map_to_fsvla_observations() -> None:
    inputs = {"observation.state": (8,), "observation.tcp_pose": (7,),
              "observation.images.front": (3, 48, 64)}
    features = map_features(inputs, (8,), _episode())
    assert features == FeatureMap(state="observation.state", tcp_pose="observation.tcp_pose",
                                  cameras={"observation.images.front": "front"},
                                  image_sizes={"observation.images.front": (48, 64)},
                                  action_size=8)
    observation = {"agent": {"qpos": np.arange(7) / 10, "gripper": np.array([0.5]),
                             "tcp_pose": np.ones(7)},
                   "images": {"front": np.full((240, 320, 3), 255, np.uint8)}}
    arrays = observation_arrays(observation, features)
    assert arrays["observation.state"].shape == (1, 8)
    assert arrays["observation.state"][0, -1] == 0.5 and arrays["observation.state"].dtype == np.float32
    assert arrays["observation.images.front"].shape == (1, 3, 240, 320)  # resized by the policy
    assert arrays["observation.images.front"].max() == 1.0


@pytest.mark.parametrize(
    ("inputs", "action", "rgb", "message"),
    [
        ({"observation.state": (14,)}, (8,), True,
         ("the checkpoint's observation.state has 14 values; on panda fsvla's has 8 "
          "(arm.j0, arm.j1")),
        ({"observation.images.top": (3, 48, 64)}, (8,), True,
         ("the checkpoint reads observation.images.top, and panda here has no camera 'top' "
          "(it has front, wrist)")),
        ({"observation.images.front": (3, 48, 64)}, (8,), False,
         "the checkpoint reads camera images (observation.images.front); run with --obs-mode rgb"),
        ({"observation.state": (8,)}, (14,), True,
         "the checkpoint's action has 14 values; the episode's joint_pos action on panda has 8"),
    ],
)
def test_mismatched_features_are_explained(inputs: dict, action: tuple, rgb: bool,
                                           message: str) -> None:
    with pytest.raises(LeRobotMismatch) as caught:
        map_features(inputs, action, _episode(rgb))
    assert str(caught.value).startswith(message)


def test_inputs_fsvla_never_provides_are_refused_at_load() -> None:
    with pytest.raises(PolicyLoadError, match="reads observation.environment_state, which "
                                              "fsvla does not provide"):
        check_inputs({"observation.state": (8,), "observation.environment_state": (4,)})


# ---------------------------------------------------------------- bad folders
def test_a_folder_that_is_no_checkpoint_is_explained(tmp_path: Path) -> None:
    with pytest.raises(PolicyLoadError, match="no such folder; give the folder a LeRobot"):
        load_policy(f"lerobot:{tmp_path / 'missing'}")
    (tmp_path / "config.json").write_text("{}")
    with pytest.raises(PolicyLoadError, match=r"not a LeRobot policy folder \(no "
                                              "model.safetensors\\)"):
        load_policy(f"lerobot:{tmp_path}")


def test_without_lerobot_the_error_names_the_install(tmp_path: Path) -> None:
    try:
        import lerobot  # noqa: F401
    except ImportError:
        pass
    else:
        pytest.skip("lerobot is installed here")
    (tmp_path / "config.json").write_text("{}")
    (tmp_path / "model.safetensors").write_bytes(b"")
    with pytest.raises(PolicyLoadError, match="LeRobot is not installed here .*pip install lerobot"):
        load_policy(f"lerobot:{tmp_path}")


def test_the_cli_reports_a_bad_folder_without_a_traceback(tmp_path: Path, short_scenario: Path,
                                                          capsys) -> None:
    pytest.importorskip("pyarrow")
    from fsvla.cli import run

    code = run(["run", "--policy", f"lerobot:{tmp_path}", "--scenarios", str(short_scenario),
                "--warmup", "0", "--workers", "0", "--no-progress", "--out", str(tmp_path / "r")])
    captured = capsys.readouterr()
    assert code == 2 and "not a LeRobot policy folder" in captured.err
    assert "Traceback" not in captured.err


# ---------------------------------------------------------------- the bar
@pytest.mark.sim
@pytest.mark.render
@pytest.mark.slow  # about a minute: importing torch, loading, rendering two cameras
def test_a_saved_tiny_act_runs_an_episode_with_rgb(tmp_path: Path, short_scenario: Path,
                                                   render_device) -> None:
    from fsvla.env import make
    from fsvla.results import ResultStore
    from tests.collect.lerobot_loader import lerobot_python

    python = lerobot_python()
    probe = subprocess.run([python, "-c", "import fsvla.env"], capture_output=True, text=True,
                           check=False)
    if probe.returncode != 0:
        why = (f"{python} has lerobot but not fsvla: pip install -e '.[sim]' into it "
               f"({probe.stderr.strip().splitlines()[-1:]})")
        if os.environ.get("FSVLA_REQUIRE_LEROBOT") == "1":
            pytest.fail(why)
        pytest.skip(why)
    # The policy acts close to the robot's start pose: its actions are valid targets.
    env = make(short_scenario, "L0", 0)
    agent = env.reset()[0]["agent"]
    start = np.concatenate([agent["qpos"], agent["gripper"]])
    mean = np.append(start[:-1], 0.5)  # a half-open gripper: noise keeps it inside [0, 1]
    cameras = [c.name for c in env.scene_spec.cameras]
    env.close()
    checkpoint = tmp_path / "act"
    offline = {**os.environ, "HF_HUB_OFFLINE": "1"}
    made = subprocess.run(
        [python, str(TINY_ACT), str(checkpoint), "--state", str(len(start)), "--action",
         str(len(start)), *[f"--camera={c}:48x64" for c in cameras],
         "--action-mean", *[str(v) for v in mean]],
        capture_output=True, text=True, env=offline, timeout=600, check=False)
    assert made.returncode == 0, made.stderr[-3000:]
    out = tmp_path / "run"
    done = subprocess.run(
        [python, "-m", "fsvla", "run", "--policy", f"lerobot:{checkpoint}", "--scenarios",
         str(short_scenario), "--obs-mode", "rgb", "--warmup", "0", "--workers", "0",
         "--no-progress", "--out", str(out)],
        capture_output=True, text=True, env=offline, timeout=600, check=False)
    assert done.returncode == 0, done.stderr[-3000:]
    with ResultStore.open(out, readonly=True) as store:
        (row,) = store.episodes()
    assert row.failure_reason is None, row.failure_detail
    assert row.steps == 20  # the whole second, in chunks of n_action_steps = 5
