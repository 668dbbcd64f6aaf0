"""Policy profiles: the built-ins, a profile file's mistakes, the observation mapping and
action decoding on synthetic arrays, and the request over openpi's protocol to servers
that accept only their example's keys (no simulator here; whole episodes are in
test_profile_episodes.py)."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("openpi_client")
from fsvla.policies import EpisodeInfo, PolicyLoadError, load_policy
from fsvla.policies.adapter import ProfileAdapter, ProfileMismatch, axis_angle
from fsvla.policies.base import ActionSchema, CameraSchema, ObservationSchema
from fsvla.policies.profile import ProfileError, builtin_profiles, load_profile
from fsvla.policies.remote import RemotePolicy
from fsvla.run.key import EpisodeKey

from .openpi_examples import JOINT_DELTA_PROFILE, Aloha, Droid, Libero, serving

JOINTS = 7
BLOCK = {"joint_pos": JOINTS, "joint_delta": JOINTS, "joint_vel": JOINTS, "ee_pose": 7,
         "ee_delta": 6}


def _episode(mode: str, arms: tuple[str, ...] = ("arm",), rgb: bool = True) -> EpisodeInfo:
    """An episode on a Panda (``arm``) or a dual Panda (``left``, ``right``) in ``mode``."""
    labels = tuple(f"{arm}.c{i}" for arm in arms for i in range(BLOCK[mode])) + tuple(
        f"{arm}.gripper" for arm in arms)
    labels = tuple(sorted(labels, key=lambda label: arms.index(label.split(".")[0])))
    cameras = (CameraSchema(name="front", height=240, width=320, mount="world"),) + tuple(
        CameraSchema(name=f"{arm}_wrist", height=240, width=320, mount=arm) for arm in arms)
    qpos = tuple(f"{arm}.j{i}" for arm in arms for i in range(JOINTS))
    return EpisodeInfo(
        key=EpisodeKey(scenario="s", suite="force", embodiment="panda", seed=0),
        policy_seed=0, instruction="lift the pot", control_rate=20.0, max_steps=20,
        action=ActionSchema(control_mode=mode, labels=labels, low=(-9.0,) * len(labels),
                            high=(9.0,) * len(labels), arms=arms),
        observation=ObservationSchema(state_layout={"qpos": qpos},
                                      cameras=cameras if rgb else ()))


def _observation(arms: int = 1) -> dict:
    rng = np.random.default_rng(0)
    half = math.sqrt(0.5)
    images = {"front": rng.integers(1, 256, (240, 320, 3), dtype=np.uint8)}
    images.update({name: rng.integers(1, 256, (240, 320, 3), dtype=np.uint8)
                   for name in (["arm_wrist"] if arms == 1 else ["left_wrist", "right_wrist"])})
    return {"agent": {"qpos": np.arange(JOINTS * arms, dtype=np.float32) / 10,
                      "gripper": np.array([0.25, 1.0][:arms], dtype=np.float32),
                      "tcp_pose": np.tile(np.array([0.1, -0.2, 0.3, half, 0, 0, half],
                                                   dtype=np.float32), arms)},
            "instruction": "lift the pot", "images": images}


# ---------------------------------------------------------------- the built-in profiles
def test_the_builtin_profiles() -> None:
    assert builtin_profiles() == ("aloha", "droid", "fsvla", "libero")
    droid, libero, aloha, fsvla = (load_profile(n) for n in ("droid", "libero", "aloha", "fsvla"))
    assert (droid.control_mode, droid.replan_steps, droid.arms) == ("joint_vel", 8, "first")
    assert (libero.control_mode, libero.replan_steps) == ("ee_delta", 5)
    assert (aloha.control_mode, aloha.replan_steps, aloha.arms) == ("joint_pos", 25, "all")
    assert fsvla.native and fsvla.control_mode is None and not fsvla.sends_images
    assert droid.action.scale == (3.0,) and libero.action.scale == (0.05,) * 3 + (0.5,) * 3


# ---------------------------------------------------------------- a profile file's mistakes
def _profile_file(tmp_path: Path, text: str) -> str:
    path = tmp_path / "mine.toml"
    path.write_text(text, encoding="utf-8")
    return str(path)


GOOD = JOINT_DELTA_PROFILE  # a profile file without a mistake


def test_a_profile_file_loads_under_its_file_name(tmp_path: Path) -> None:
    profile = load_profile(_profile_file(tmp_path, GOOD))
    assert profile.name == "mine" and profile.control_mode == "joint_delta"
    assert [p.part for p in profile.observation.state[0].parts] == ["joints", "gripper"]


@pytest.mark.parametrize(("text", "says"), [
    (GOOD.replace('control_mode = "joint_delta"', 'control_mode = "joint_delta"\nscael = 2'),
     ("`action.scael` is not a profile setting; remove it or correct its name "
     "(did you mean `scale`?)")),
    (GOOD.replace('"joints", "gripper"', '"joints", "elbow"'),
     "`observation.state[0].parts[1].part`: Input should be 'joints', 'gripper'"),
    (GOOD.replace('control_mode = "joint_delta"', 'control_mode = "joint_velocity"'),
     ("`action.control_mode`: Input should be 'joint_pos', 'joint_delta', 'joint_vel', "
     "'ee_pose' or 'ee_delta'; got 'joint_velocity'")),
    (GOOD[:GOOD.index("[action]")],
     "`action` is missing; add its table (or set native = true)"),
    (GOOD.replace('key = "qpos"', 'key = "task"'), "the key `task` is sent twice"),
    (GOOD + "clip = [1.0, -1.0]\n", "`action.clip`: `clip` is [low, high] with low < high"),
    (GOOD.replace("[action]", "[action]\ngripper = { closed = 1.0, open = 1.0 }"),
     "`action.gripper`: `closed` and `open` must differ (both are 1.0)"),
    (GOOD.replace("replan_steps = 4", "replan_steps = 4 4"), "not valid TOML"),
])
def test_a_profile_file_with_a_mistake_names_the_file_and_the_setting(
        tmp_path: Path, text: str, says: str) -> None:
    path = _profile_file(tmp_path, text)
    with pytest.raises(ProfileError) as caught:
        load_profile(path)
    assert str(caught.value).startswith(f"{path}: ") and says in str(caught.value)


def test_several_mistakes_are_listed_together(tmp_path: Path) -> None:
    text = GOOD.replace("replan_steps = 4", "replan_steps = 0\narm = 'first'")
    with pytest.raises(ProfileError, match=r"mine.toml: 2 problems:\n  `replan_steps`: Input "
                                           r"should be greater than or equal to 1; got 0\n  "
                                           r"`arm` is not a profile setting.*`arms`"):
        load_profile(_profile_file(tmp_path, text))


def test_an_unknown_profile_and_a_profile_without_a_server() -> None:
    with pytest.raises(ProfileError, match="not a built-in profile or a .toml file; did you "
                                           "mean `droid`"):
        load_profile("drod")
    with pytest.raises(ProfileError, match="nosuch.toml: cannot read it"):
        load_profile("nosuch.toml")
    with pytest.raises(PolicyLoadError, match="--policy-profile droid: profiles map the keys "
                                              "of a policy server"):
        load_policy("random", profile="droid")


# ---------------------------------------------------------------- mapping, on arrays
def test_droid_request_and_actions() -> None:
    adapter = ProfileAdapter(load_profile("droid"), _episode("joint_vel"))
    request = adapter.request(_observation())
    assert set(request) == Droid.KEYS and request["prompt"] == "lift the pot"
    image = request["observation/exterior_image_1_left"]
    assert image.shape == (224, 224, 3) and image.dtype == np.uint8
    assert not image[:27].any() and not image[-27:].any() and image[28:196].all()  # padded
    assert request["observation/joint_position"].dtype == np.float64
    assert request["observation/joint_position"].tolist() == pytest.approx(
        np.arange(7) / 10, abs=1e-6)
    assert request["observation/gripper_position"].tolist() == [0.75]  # DROID: 1 closed
    actions = adapter.actions([[0.5, -2.0, 0, 0, 0, 0, 0, 0.6],
                               [0.1, 0, 0, 0, 0, 0, 0, 0.4]], _observation())
    assert actions[0].tolist() == pytest.approx([1.5, -3.0, 0, 0, 0, 0, 0, 0.0])
    assert actions[1].tolist() == pytest.approx([0.3, 0, 0, 0, 0, 0, 0, 1.0])
    with pytest.raises(ValueError, match=r"droid: the server's actions have shape \(10, 7\); "
                                         r"expected \(H, 8\): 7 joint_vel \+ 1 gripper \(arm\)"):
        adapter.actions(np.zeros((10, 7)), _observation())


def test_libero_state_is_position_axis_angle_and_fingers() -> None:
    adapter = ProfileAdapter(load_profile("libero"), _episode("ee_delta"))
    request = adapter.request(_observation())
    assert set(request) == Libero.KEYS
    state = request["observation/state"]
    assert state.dtype == np.float64 and state.shape == (8,)
    assert state[:3] == pytest.approx([0.1, -0.2, 0.3], abs=1e-6)
    assert state[3:6] == pytest.approx([0.0, 0.0, math.pi / 2], abs=1e-5)  # yaw 90°
    assert state[6:] == pytest.approx([0.01, -0.01])  # a quarter open
    actions = adapter.actions([[1.0, 0, -3.0, 0, 0, 0.2, -1.0]], _observation())
    assert actions[0].tolist() == pytest.approx([0.05, 0, -0.05, 0, 0, 0.1, 1.0])
    assert axis_angle([-1.0, 0, 0, 0]).tolist() == [0, 0, 0]
    assert axis_angle([0.0, 0, 0, 1.0]).tolist() == pytest.approx([0, 0, math.pi])


def test_aloha_sends_chw_views_and_per_arm_state_and_takes_absolute_joints() -> None:
    adapter = ProfileAdapter(load_profile("aloha"), _episode("joint_pos", ("left", "right")))
    observation = _observation(arms=2)
    request = adapter.request(observation)
    assert set(request) == {"state", "images"}
    assert set(request["images"]) == {"cam_high", "cam_left_wrist", "cam_right_wrist"}
    assert all(v.shape == (3, 224, 224) and v.dtype == np.uint8
               for v in request["images"].values())
    assert request["images"]["cam_left_wrist"].transpose(1, 2, 0)[112].tolist()[:3] != [[0] * 3]
    state = request["state"]
    assert state.shape == (16,) and state.dtype == np.float64
    assert state[[7, 15]].tolist() == [0.25, 1.0] and state[8] == pytest.approx(0.7)
    row = np.arange(16) / 100
    assert adapter.actions(row, observation)[0].tolist() == pytest.approx(row)
    single = ProfileAdapter(load_profile("aloha"), _episode("joint_pos"))  # wrist views optional
    assert set(single.request(_observation())["images"]) == {"cam_high", "cam_left_wrist"}


def test_a_single_arm_profile_drives_the_first_arm_and_holds_the_other() -> None:
    adapter = ProfileAdapter(load_profile("droid"), _episode("joint_vel", ("left", "right")))
    observation = _observation(arms=2)
    assert adapter.request(observation)["observation/joint_position"].shape == (7,)
    (row,) = adapter.actions([[0.1] * 7 + [1.0]], observation)
    assert row.tolist() == pytest.approx([0.3] * 7 + [0.0] + [0.0] * 7 + [1.0])


@pytest.mark.parametrize(("profile", "episode", "says"), [
    ("droid", _episode("joint_pos"), ("profile droid decodes joint_vel actions, but the episode "
                                     "runs joint_pos: run with --control-mode joint_vel")),
    ("libero", _episode("ee_delta", rgb=False), ("profile libero sends camera images "
                                                "(observation/image); run with --obs-mode rgb")),
])
def test_a_profile_that_cannot_serve_the_episode_says_why(profile: str, episode: EpisodeInfo,
                                                          says: str) -> None:
    with pytest.raises(ProfileMismatch, match=re.escape(says)):
        ProfileAdapter(load_profile(profile), episode)


# ---------------------------------------------------------------- over openpi's protocol
@pytest.mark.parametrize(("profile", "server", "episode", "arms"), [
    ("droid", Droid(), _episode("joint_vel"), 1),
    ("libero", Libero(), _episode("ee_delta"), 1),
    ("aloha", Aloha(), _episode("joint_pos", ("left", "right")), 2),
])
def test_each_example_server_accepts_its_profile(profile: str, server, episode: EpisodeInfo,
                                                 arms: int) -> None:
    with serving(server) as (handler, uri):
        policy = load_policy(uri, profile=profile)
        assert isinstance(policy, RemotePolicy)
        policy.reset(episode)
        chunk = policy.act(_observation(arms))
        policy.close()
    assert not handler.errors and len(handler.requests) == 1
    assert chunk.shape[1] == len(episode.action.labels) and chunk.shape[0] >= 10


def test_an_example_server_refuses_fsvla_s_own_keys() -> None:
    with serving(Droid()) as (handler, uri):
        policy = load_policy(uri)
        policy.reset(_episode("joint_vel"))
        with pytest.raises(RuntimeError, match="KeyError"):
            policy.act(_observation())
    assert "missing ['observation/exterior_image_1_left'" in handler.errors[0]


# ---------------------------------------------------------------- fsvla run's options
@pytest.mark.parametrize(("args", "says"), [
    (["--policy-profile", "drod"], ("error: --policy-profile 'drod': not a built-in profile or "
                                   "a .toml file; did you mean `droid`?")),
    (["--policy-profile", "droid", "--policy", "random"],
     ("error: --policy-profile maps the keys of a policy server (--policy ws://host:port); "
     "--policy random is none")),
    (["--policy-profile", "droid", "--control-mode", "joint_pos"],
     ("--control-mode: profile droid decodes its server's actions as joint_vel, not joint_pos; "
     "leave --control-mode out")),
    (["--policy-profile", "libero", "--obs-mode", "state"],
     "--obs-mode: profile libero sends camera images; it needs --obs-mode rgb"),
    (["--policy-profile", "{bad}"], ("mine.toml: `action.scael` is not a profile setting; "
                                    "remove it or correct its name (did you mean `scale`?)")),
])
def test_fsvla_run_refuses_a_bad_profile_with_exit_2(tmp_path: Path, capsys, args: list[str],
                                                     says: str) -> None:
    from fsvla.cli import run

    bad = _profile_file(tmp_path, GOOD + "scael = 2\n")
    argv = ["run", "--policy", "ws://127.0.0.1:9", "--scenarios", "short_lift", "--workers", "0",
            "--out", str(tmp_path / "never")]
    for option, value in zip(args[::2], args[1::2]):
        if option in argv:  # replace --policy
            argv[argv.index(option) + 1] = value
        else:
            argv += [option, value.replace("{bad}", bad)]
    assert run(argv) == 2
    err = capsys.readouterr().err
    assert says in " ".join(err.split()) and "Traceback" not in err
    assert not (tmp_path / "never").exists()
