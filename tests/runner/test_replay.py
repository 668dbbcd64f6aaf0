"""Replaying an episode from its run folder reproduces its trace exactly."""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import pytest

from fsvla.results import ResultStore
from fsvla.runner import ReplayInputError, replay_episode
from fsvla.runner.replay import compare_traces

from .conftest import policy, run_into

pytestmark = pytest.mark.sim


@pytest.fixture(scope="module")
def random_run(make_run_config, tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("random_run")
    config = make_run_config(policy="random", levels=("L0", "L1"), languages=("W0", "W3"),
                             episodes=2, seeds=(0, 1), warmup=1)
    run_into(out, config)
    return out


def episode_ids(out: Path) -> list[str]:
    with ResultStore.open(out, readonly=True) as store:
        return sorted(store.recorded_ids())


def test_every_episode_replays_identically_from_its_actions(random_run: Path) -> None:
    ids = episode_ids(random_run)
    assert len(ids) == 9
    for episode_id in ids:
        result = replay_episode(random_run, episode_id)
        assert result.identical, (episode_id, result.differences)
        assert result.replayed_steps == result.recorded_steps == 20


def test_a_deterministic_policy_replays_identically(random_run: Path) -> None:
    result = replay_episode(random_run, "short_lift-L1-W3-V0-s1-e001", with_policy=True)
    assert result.mode == "policy" and result.identical, result.differences


def test_a_faulted_episode_replays_its_steps(make_run_config, tmp_path: Path) -> None:
    run_into(tmp_path, make_run_config(policy=policy("Nan")))
    (episode_id,) = episode_ids(tmp_path)
    for with_policy in (False, True):
        result = replay_episode(tmp_path, episode_id, with_policy=with_policy)
        assert result.identical, result.differences
        assert result.recorded_fault == "invalid_action" and result.replayed_steps == 2
    assert replay_episode(tmp_path, episode_id, with_policy=True).replay_fault == "invalid_action"


def test_a_changed_trace_is_found(random_run: Path) -> None:
    with ResultStore.open(random_run, readonly=True) as store:
        recorded = store.trace("short_lift-L0-W0-V0-s0-e000")
    changed = copy.deepcopy(recorded)
    changed["margins"][7][1] = float(np.nextafter(recorded["margins"][7][1], np.inf))  # one ulp
    assert compare_traces(recorded, changed) == ["margins differ from step 8 on"]
    assert compare_traces(recorded, {**recorded, "success": not recorded["success"]})


def test_unknown_episodes_and_folders_are_input_errors(random_run: Path, tmp_path: Path) -> None:
    with pytest.raises(ReplayInputError, match="did you mean short_lift-L0-W0-V0-s0-e000"):
        replay_episode(random_run, "short_lift-L0-W0-V0-s0-e00")
    with pytest.raises(ReplayInputError, match="holds no run"):
        replay_episode(tmp_path, "x")


@pytest.mark.render
@pytest.mark.slow  # about 10-40 s: rendering on a CPU device (lavapipe)
def test_a_vision_episode_replays_with_a_video(make_run_config, tmp_path: Path,
                                               render_device) -> None:
    config = make_run_config(visions=("V2",), obs_mode="rgb")
    run_into(tmp_path / "run", config)
    (episode_id,) = episode_ids(tmp_path / "run")
    result = replay_episode(tmp_path / "run", episode_id, video=tmp_path / "episode.mp4")
    assert result.identical, result.differences
    assert result.video is not None and result.video.exists(), result.video_note
    if result.video.suffix == ".mp4":
        assert result.video.stat().st_size > 1000
    else:  # no imageio-ffmpeg: PNG frames, one per observation
        assert len(list(result.video.glob("*.png"))) == 21
