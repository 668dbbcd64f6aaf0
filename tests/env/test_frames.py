"""Rendering what is looked at: lazy pictures, the cameras of a run, the render count of
a chunking policy, and episodes identical whichever steps are rendered."""

from __future__ import annotations

import copy
import pickle
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from fsvla.compiler.scene import Pose, SceneCamera

from fsvla.env.frames import LazyImages, StaleFrameError
from fsvla.sim.cameras import camera_selection, check_camera_names, parse_resolution

PICTURE = np.zeros((2, 3, 3), dtype=np.uint8)


def _lazy(calls: list[int]) -> LazyImages:
    def render() -> dict[str, np.ndarray]:
        calls.append(1)
        return {"front": PICTURE, "wrist": PICTURE + 1}

    return LazyImages(["front", "wrist"], render)


def test_lazy_images_render_once_at_the_first_read_of_a_picture() -> None:
    calls: list[int] = []
    images = _lazy(calls)
    assert list(images) == ["front", "wrist"] and len(images) == 2 and "front" in images
    assert isinstance(images, dict) and not images.rendered and calls == []
    assert images["wrist"][0, 0, 0] == 1 and images.rendered and calls == [1]
    assert dict(images)["front"] is PICTURE and {**images}["wrist"][0, 0, 0] == 1
    assert calls == [1]


@pytest.mark.parametrize("read", [
    lambda x: dict(x), lambda x: {**x}, lambda x: list(x.values()), lambda x: list(x.items()),
    lambda x: x.get("front"), lambda x: x.copy(), lambda x: pickle.loads(pickle.dumps(x)),
    lambda x: copy.deepcopy(x), lambda x: x == {"front": PICTURE},
])
def test_every_way_of_reading_a_picture_renders(read: Any) -> None:
    calls: list[int] = []
    result = read(_lazy(calls))
    assert calls == [1] and result is not None
    if isinstance(result, dict):
        assert type(result) is dict and all(v is not None for v in result.values())


def test_parse_resolution() -> None:
    assert parse_resolution("160x120") == (160, 120) == parse_resolution(" 160 X 120 ")
    assert parse_resolution((64, 48)) == (64, 48)
    for bad in ("160", "160x", "x120", "160by120", "-1x5", "0x10", "5000x10", (1, 2, 3)):
        with pytest.raises(ValueError, match="resolution"):
            parse_resolution(bad)  # type: ignore[arg-type]


def test_camera_names_are_checked_with_a_suggestion() -> None:
    assert check_camera_names(["wrist", "front", "wrist"], ["front", "wrist"]) == ("wrist", "front")
    with pytest.raises(ValueError, match="unknown camera 'frnt'; did you mean 'front'"):
        check_camera_names(["frnt"], ["front", "wrist"])
    with pytest.raises(ValueError, match="name at least one camera"):
        check_camera_names([" "], ["front"])


def test_camera_selection_keeps_the_scene_order_and_resizes() -> None:
    def camera(name: str) -> SceneCamera:
        return SceneCamera(name=name, parent="world", pose=Pose(position=(0, 0, 1)), fovy=1.0,
                           width=320, height=240, near=0.01, far=10.0)

    cameras = (camera("front"), camera("wrist"))
    assert camera_selection(cameras) == cameras
    chosen = camera_selection(cameras, ["wrist", "front"], (160, 120))
    assert [(c.name, c.width, c.height, c.fovy) for c in chosen] == [
        ("front", 160, 120, 1.0), ("wrist", 160, 120, 1.0)]


# --- in the environment -------------------------------------------------------------------


@pytest.fixture(scope="module")
def short(short_scenario: Path) -> Path:
    return short_scenario


def _hold(env: Any, obs: dict[str, Any]) -> np.ndarray:
    from fsvla.policies.simple import hold_action

    joints = [len(a.joint_indices) for a in env.built.robot.arms.values()]
    return hold_action(obs, env.codec.mode.value, joints)


def _moves(env: Any, obs: dict[str, Any], steps: int) -> list[np.ndarray]:
    """A reach down and sideways, so the pictures change from step to step."""
    action = _hold(env, obs)
    return [action + np.concatenate([np.full(len(action) - 1, 0.02 * i), [0.0]])
            for i in range(steps)]


@pytest.mark.sim
@pytest.mark.render
def test_lazy_pictures_are_the_eager_ones_of_the_steps_read(short: Path, render_device) -> None:
    from fsvla.env import make

    lazy = make(short, obs_mode="rgb", vision="V4", seed=1, lazy_images=True)
    eager = make(short, obs_mode="rgb", vision="V4", seed=1)
    obs_l, _ = lazy.reset()
    obs_e, _ = eager.reset()
    assert isinstance(obs_l["images"], LazyImages) and type(obs_e["images"]) is dict
    assert eager.frames_rendered == 1 and lazy.frames_rendered == 0
    compared = 0
    for i, action in enumerate(_moves(lazy, obs_l, 12)):
        if i % 4 == 0:  # read every fourth step's pictures only
            for name in obs_e["images"]:
                assert np.array_equal(obs_l["images"][name], obs_e["images"][name])
            compared += 1
        obs_l, *_ = lazy.step(action)
        obs_e, *_ = eager.step(action)
    assert compared == 3 and lazy.frames_rendered == 3 and eager.frames_rendered == 13
    assert not np.array_equal(obs_e["images"]["front"], eager.reset()[0]["images"]["front"])


@pytest.mark.sim
@pytest.mark.render
def test_pictures_of_a_past_step_are_refused(short: Path, render_device) -> None:
    from fsvla.env import make

    env = make(short, obs_mode="rgb", cameras=["front"], resolution="64x48", lazy_images=True)
    old, _ = env.reset()
    assert old["images"]["front"].shape == (48, 64, 3)  # read in time: kept
    unread, *_ = env.step(_hold(env, old))
    env.step(_hold(env, old))
    assert old["images"]["front"].shape == (48, 64, 3)
    with pytest.raises(StaleFrameError, match="read obs\\['images'\\] before the next step"):
        unread["images"]["front"]
    assert env.observation_space["images"]["front"].shape == (48, 64, 3)
    assert list(env.built.cameras) == ["front"] and env.config.cameras == ("front",)


@pytest.mark.sim
@pytest.mark.render
def test_the_state_trace_is_the_same_whichever_steps_are_rendered(short: Path,
                                                                  render_device) -> None:
    from fsvla.env import make

    def episode(**options: Any) -> tuple[dict[str, Any], list[np.ndarray]]:
        env = make(short, control_mode="joint_pos", **options)
        obs, _ = env.reset()
        states = []
        for i, action in enumerate(_moves(env, obs, 20)):
            if "images" in obs and i % 7 == 0:
                obs["images"]["front"]
            obs, *_ = env.step(action)
            states.append(env.built.state())
        return env.episode_record().to_dict(), states

    state_only = episode()
    lazy = episode(obs_mode="rgb", lazy_images=True)
    eager = episode(obs_mode="rgb")
    for other in (lazy, eager):
        assert other[0] == state_only[0]
        assert all(np.array_equal(a, b) for a, b in zip(other[1], state_only[1], strict=True))


class LookingChunks:
    """Reads every picture it is shown and holds still in chunks of ten actions."""

    name = "looking-chunks"

    def reset(self, episode: Any) -> None:
        self.sizes = [sum(1 for label in episode.action.labels if label.startswith(f"{arm}.")
                          and label != f"{arm}.gripper") for arm in episode.action.arms]

    def act(self, observation: dict[str, Any]) -> np.ndarray:
        from fsvla.policies.simple import hold_action

        assert all(image.ndim == 3 for image in observation["images"].values())
        return np.tile(hold_action(observation, "joint_pos", self.sizes), (10, 1))


@pytest.mark.sim
@pytest.mark.render
def test_a_ten_step_chunk_policy_renders_one_step_in_ten(short: Path, tmp_path: Path,
                                                         render_device, monkeypatch) -> None:
    from fsvla.runner import execute_run, make_backend, make_config, prepare_run
    from fsvla.sim.builder import BuiltScene

    renders: list[int] = []
    original = BuiltScene.render_views

    def counted(self: BuiltScene, names: Any = None) -> dict[str, np.ndarray]:
        renders.append(1)
        return original(self, names)

    monkeypatch.setattr(BuiltScene, "render_views", counted)
    config = make_config(policy=f"{__file__}:LookingChunks", scenarios=(str(short),),
                         warmup=0, obs_mode="rgb", resolution=(64, 48))
    result = execute_run(prepare_run(config), tmp_path / "run", make_backend("process", config, 0))
    assert result.recorded == 1 and not result.faults
    assert len(renders) == 2  # 20 steps: the pictures at the reset and after step 10


class RememberingChunks(LookingChunks):
    """Keeps every observation it is shown and reads the one before at each query (a
    frame history, as policies with several observation steps keep)."""

    name = "remembering-chunks"

    def reset(self, episode: Any) -> None:
        super().reset(episode)
        self.seen: list[dict[str, Any]] = []

    def act(self, observation: dict[str, Any]) -> np.ndarray:
        from fsvla.policies.simple import hold_action

        self.seen.append(observation)  # its pictures are not read now
        if len(self.seen) > 1:
            assert self.seen[-2]["images"]["front"].shape == (48, 64, 3)
        return np.tile(hold_action(observation, "joint_pos", self.sizes), (10, 1))


@pytest.mark.sim
@pytest.mark.render
def test_a_policy_may_read_an_observation_it_kept(short: Path, tmp_path: Path,
                                                  render_device) -> None:
    from fsvla.runner import execute_run, make_backend, make_config, prepare_run

    config = make_config(policy=f"{__file__}:RememberingChunks", scenarios=(str(short),),
                         warmup=0, obs_mode="rgb", resolution=(64, 48))
    result = execute_run(prepare_run(config), tmp_path / "run", make_backend("process", config, 0))
    assert result.recorded == 1 and not result.faults, dict(result.faults)


@pytest.mark.sim
@pytest.mark.render
def test_a_default_env_keeps_every_observation_whole(short: Path, render_device) -> None:
    from fsvla.env import make

    env = make(short, obs_mode="rgb", cameras=["front"], resolution="64x48")
    first, _ = env.reset()
    env.step(_hold(env, first))
    assert type(first["images"]) is dict and first["images"]["front"].shape == (48, 64, 3)
