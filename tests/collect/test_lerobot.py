"""The LeRobot dataset writer: layout, metadata, videos, resume after a crash."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

pa = pytest.importorskip("pyarrow")
import pyarrow.parquet as pq

from fsvla.collect.lerobot import DatasetMismatch, Frame, LeRobotWriter, features

from .lerobot_loader import load_with_lerobot

CAMERAS = {"front": (16, 24), "wrist": (16, 24)}


def _features(cameras=CAMERAS) -> dict:
    return features(["j1", "j2", "gripper"], ["x", "y", "z", "qw", "qx", "qy", "qz"],
                    ["j1", "j2", "gripper"], cameras, 20.0)


def _frames(n: int, value: float, cameras=CAMERAS) -> list[Frame]:
    return [Frame(state=np.full(3, value + t, np.float32), tcp_pose=np.zeros(7, np.float32),
                  action=np.full(3, value - t, np.float32),
                  images={c: np.full((h, w, 3), (t * 20) % 255, np.uint8)
                          for c, (h, w) in cameras.items()})
            for t in range(n)]


def _writer(root: Path, cameras=CAMERAS) -> LeRobotWriter:
    return LeRobotWriter(root, fps=20.0, robot_type="panda", features=_features(cameras))


def test_two_episodes_make_a_complete_dataset(tmp_path: Path) -> None:
    writer = _writer(tmp_path)
    assert writer.add_episode(_frames(5, 0.0), "Lift the pot.") == 0
    assert writer.add_episode(_frames(3, 10.0), "Lift the pot.") == 1
    info = json.loads((tmp_path / "meta/info.json").read_text())
    assert (info["total_episodes"], info["total_frames"], info["total_tasks"],
            info["total_videos"], info["splits"]) == (2, 8, 1, 4, {"train": "0:2"})
    assert info["features"]["observation.images.front"]["shape"] == [16, 24, 3]
    table = pq.read_table(tmp_path / "data/chunk-000/episode_000001.parquet")
    assert table.column("index").to_pylist() == [5, 6, 7]  # global frame index continues
    assert table.column("frame_index").to_pylist() == [0, 1, 2]
    assert table.column("timestamp").to_pylist() == pytest.approx([0.0, 0.05, 0.1])
    assert table.column("observation.state").to_pylist()[2] == [12.0, 12.0, 12.0]
    episodes = [json.loads(line) for line in (tmp_path / "meta/episodes.jsonl").read_text().splitlines()]
    assert episodes == [{"episode_index": 0, "tasks": ["Lift the pot."], "length": 5},
                        {"episode_index": 1, "tasks": ["Lift the pot."], "length": 3}]
    stats = json.loads((tmp_path / "meta/episodes_stats.jsonl").read_text().splitlines()[1])
    assert stats["stats"]["observation.state"]["max"] == [12.0, 12.0, 12.0]
    assert np.asarray(stats["stats"]["observation.images.front"]["mean"]).shape == (3, 1, 1)


def test_videos_hold_every_frame(tmp_path: Path) -> None:
    imageio = pytest.importorskip("imageio.v2")
    pytest.importorskip("imageio_ffmpeg")
    _writer(tmp_path).add_episode(_frames(6, 0.0), "t")
    video = tmp_path / "videos/chunk-000/observation.images.wrist/episode_000000.mp4"
    reader = imageio.get_reader(video)
    frames = [frame for frame in reader]
    assert len(frames) == 6 and frames[0].shape == (16, 24, 3)


def test_a_reopened_dataset_resumes_and_drops_what_a_crash_left(tmp_path: Path) -> None:
    _writer(tmp_path).add_episode(_frames(4, 0.0), "t")
    # A crash after episode 1's data file was written, before its metadata:
    orphan = tmp_path / "data/chunk-000/episode_000001.parquet"
    orphan.write_bytes(b"partial")
    (tmp_path / "data/chunk-000/episode_000002.parquet.tmp").write_bytes(b"x")
    writer = _writer(tmp_path)
    assert writer.episodes == 1 and not orphan.exists()
    assert not list(tmp_path.glob("data/*/*.tmp"))
    assert writer.add_episode(_frames(2, 0.0), "another task") == 1
    info = json.loads((tmp_path / "meta/info.json").read_text())
    assert (info["total_episodes"], info["total_frames"], info["total_tasks"]) == (2, 6, 2)
    tasks = [json.loads(line) for line in (tmp_path / "meta/tasks.jsonl").read_text().splitlines()]
    assert tasks == [{"task_index": 0, "task": "t"}, {"task_index": 1, "task": "another task"}]


def test_other_features_are_refused(tmp_path: Path) -> None:
    _writer(tmp_path).add_episode(_frames(2, 0.0), "t")
    with pytest.raises(DatasetMismatch, match="differing: observation.images.wrist"):
        _writer(tmp_path, cameras={"front": (16, 24)})


def test_state_only_datasets_have_no_videos(tmp_path: Path) -> None:
    writer = _writer(tmp_path, cameras={})
    writer.add_episode(_frames(3, 0.0, cameras={}), "t")
    info = json.loads((tmp_path / "meta/info.json").read_text())
    assert info["video_path"] is None and info["total_videos"] == 0
    assert not (tmp_path / "videos").exists()


def test_lerobot_reads_the_dataset(tmp_path: Path) -> None:
    """LeRobot's own loader reads every frame, state and picture as written."""
    root = tmp_path / "demo"
    writer = _writer(root)
    writer.add_episode(_frames(5, 0.0), "Lift the pot.")
    writer.add_episode(_frames(4, 10.0), "Put the pot down.")
    seen = load_with_lerobot(root)
    assert (seen["version"], seen["episodes"], seen["frames"], seen["fps"]) == ("v2.1", 2, 9, 20)
    assert seen["shapes"]["observation.state"] == [3]
    assert seen["shapes"]["observation.images.front"] == [3, 16, 24]  # CHW float in [0, 1]
    assert seen["tasks"] == ["Lift the pot.", "Put the pot down."]
    assert seen["episode_index"] == [0] * 5 + [1] * 4
    assert [s[0] for s in seen["state"]] == [0, 1, 2, 3, 4, 10, 11, 12, 13]
    # frame t of each episode is the grey level 20 t (H.264 moves it by a few levels)
    expected = [20 * t / 255 for t in (*range(5), *range(4))]
    assert seen["image_means"]["observation.images.wrist"] == pytest.approx(expected, abs=0.03)
