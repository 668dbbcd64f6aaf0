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


def _episodes(root: Path) -> list[dict]:
    return pq.read_table(root / "meta/episodes/chunk-000/file-000.parquet").to_pylist()


def test_two_episodes_make_a_complete_dataset(tmp_path: Path) -> None:
    writer = _writer(tmp_path)
    assert writer.add_episode(_frames(5, 0.0), "Lift the pot.") == 0
    assert writer.add_episode(_frames(3, 10.0), "Lift the pot.") == 1
    info = json.loads((tmp_path / "meta/info.json").read_text())
    assert (info["codebase_version"], info["total_episodes"], info["total_frames"],
            info["total_tasks"], info["splits"]) == ("v3.0", 2, 8, 1, {"train": "0:2"})
    assert info["features"]["observation.images.front"]["shape"] == [16, 24, 3]
    # Both episodes share one data file; the global frame index continues.
    table = pq.read_table(tmp_path / "data/chunk-000/file-000.parquet")
    assert table.column("index").to_pylist() == list(range(8))
    assert table.column("episode_index").to_pylist() == [0] * 5 + [1] * 3
    assert table.column("frame_index").to_pylist()[5:] == [0, 1, 2]
    assert table.column("timestamp").to_pylist()[5:] == pytest.approx([0.0, 0.05, 0.1])
    assert table.column("observation.state").to_pylist()[7] == [12.0, 12.0, 12.0]
    episodes = _episodes(tmp_path)
    assert [(e["episode_index"], e["tasks"], e["length"], e["dataset_from_index"],
             e["dataset_to_index"]) for e in episodes] == [(0, ["Lift the pot."], 5, 0, 5),
                                                          (1, ["Lift the pot."], 3, 5, 8)]
    # One video per camera; each episode's segment follows the one before.
    key = "videos/observation.images.front"
    assert [(e[f"{key}/file_index"], e[f"{key}/from_timestamp"], e[f"{key}/to_timestamp"])
            for e in episodes] == [(0, 0.0, 0.25), (0, 0.25, pytest.approx(0.4))]
    assert episodes[1]["stats/observation.state/max"] == [12.0, 12.0, 12.0]
    assert np.asarray(episodes[0]["stats/observation.images.front/mean"]).shape == (3, 1, 1)
    stats = json.loads((tmp_path / "meta/stats.json").read_text())
    assert stats["observation.state"]["max"] == [12.0, 12.0, 12.0]
    assert stats["observation.state"]["count"] == [8]
    actions = [0, -1, -2, -3, -4, 10, 9, 8]
    assert stats["action"]["mean"] == pytest.approx([np.mean(actions)] * 3)
    assert stats["action"]["std"] == pytest.approx([np.std(actions)] * 3)
    assert set(stats["action"]) >= {"min", "max", "mean", "std", "count", "q01", "q99"}
    tasks = pq.read_table(tmp_path / "meta/tasks.parquet")
    assert tasks.column("task_index").to_pylist() == [0]
    assert not (tmp_path / ".staging").exists()


def test_videos_hold_every_frame_of_every_episode(tmp_path: Path) -> None:
    imageio = pytest.importorskip("imageio.v2")
    pytest.importorskip("imageio_ffmpeg")
    writer = _writer(tmp_path)
    writer.add_episode(_frames(6, 0.0), "t")
    writer.add_episode(_frames(4, 0.0), "t")
    video = tmp_path / "videos/observation.images.wrist/chunk-000/file-000.mp4"
    frames = imageio.mimread(video, memtest=False)
    assert len(frames) == 10 and frames[0].shape == (16, 24, 3)
    levels = [float(f.mean()) for f in frames]
    assert levels == pytest.approx([20 * t for t in (*range(6), *range(4))], abs=3)


def test_a_reopened_dataset_resumes_and_drops_what_a_crash_left(tmp_path: Path) -> None:
    _writer(tmp_path).add_episode(_frames(4, 0.0), "t")
    before = (tmp_path / "data/chunk-000/file-000.parquet").read_bytes()
    # A crash while episode 1 was being staged, before its commit:
    staged = tmp_path / ".staging/data/chunk-000/file-000.parquet"
    staged.parent.mkdir(parents=True)
    staged.write_bytes(b"partial")
    writer = _writer(tmp_path)
    assert writer.episodes == 1 and not (tmp_path / ".staging").exists()
    assert (tmp_path / "data/chunk-000/file-000.parquet").read_bytes() == before
    assert writer.add_episode(_frames(2, 0.0), "another task") == 1
    info = json.loads((tmp_path / "meta/info.json").read_text())
    assert (info["total_episodes"], info["total_frames"], info["total_tasks"]) == (2, 6, 2)
    tasks = pq.read_table(tmp_path / "meta/tasks.parquet").to_pylist()
    assert [(t["task_index"], t["__index_level_0__"]) for t in tasks] == [(0, "t"),
                                                                         (1, "another task")]


def test_a_commit_a_crash_interrupted_is_finished(tmp_path: Path, monkeypatch) -> None:
    """A crash between moving the staged files into place: reopening completes the move."""
    _writer(tmp_path).add_episode(_frames(4, 0.0), "t")
    moved: list[str] = []

    def crash_after_two(self, staged):
        import os as os_module

        for relative in staged[:2]:
            os_module.replace(self.root / ".staging" / relative, self.root / relative)
            moved.append(relative)
        raise KeyboardInterrupt

    writer = _writer(tmp_path)
    monkeypatch.setattr(LeRobotWriter, "_finish", crash_after_two)
    with pytest.raises(KeyboardInterrupt):
        writer.add_episode(_frames(3, 0.0), "t")
    monkeypatch.undo()
    assert len(moved) == 2 and (tmp_path / ".staging/commit.json").exists()
    reopened = _writer(tmp_path)
    assert reopened.episodes == 2 and not (tmp_path / ".staging").exists()
    table = pq.read_table(tmp_path / "data/chunk-000/file-000.parquet")
    assert table.num_rows == 7 and len(_episodes(tmp_path)) == 2


def test_a_full_file_makes_way_for_the_next(tmp_path: Path, monkeypatch) -> None:
    import fsvla.collect.lerobot as module

    monkeypatch.setattr(module, "DATA_FILE_MB", 1e-6)
    monkeypatch.setattr(module, "VIDEO_FILE_MB", 1e-6)
    writer = _writer(tmp_path)
    writer.add_episode(_frames(3, 0.0), "t")
    writer.add_episode(_frames(2, 0.0), "t")
    assert pq.read_table(tmp_path / "data/chunk-000/file-001.parquet").column(
        "index").to_pylist() == [3, 4]
    second = _episodes(tmp_path)[1]
    key = "videos/observation.images.front"
    assert (second["data/file_index"], second[f"{key}/file_index"],
            second[f"{key}/from_timestamp"]) == (1, 1, 0.0)


def test_a_v21_dataset_is_refused(tmp_path: Path) -> None:
    _writer(tmp_path).add_episode(_frames(2, 0.0), "t")
    info = json.loads((tmp_path / "meta/info.json").read_text())
    (tmp_path / "meta/info.json").write_text(json.dumps(info | {"codebase_version": "v2.1"}))
    with pytest.raises(DatasetMismatch, match="format v2.1.*convert_dataset_v21_to_v30"):
        _writer(tmp_path)


def test_other_features_are_refused(tmp_path: Path) -> None:
    _writer(tmp_path).add_episode(_frames(2, 0.0), "t")
    with pytest.raises(DatasetMismatch, match="differing: observation.images.wrist"):
        _writer(tmp_path, cameras={"front": (16, 24)})


def test_state_only_datasets_have_no_videos(tmp_path: Path) -> None:
    writer = _writer(tmp_path, cameras={})
    writer.add_episode(_frames(3, 0.0, cameras={}), "t")
    info = json.loads((tmp_path / "meta/info.json").read_text())
    assert info["video_path"] is None
    assert not (tmp_path / "videos").exists()


def test_lerobot_reads_the_dataset(tmp_path: Path) -> None:
    """LeRobot's own loader reads every frame, state and picture as written."""
    root = tmp_path / "demo"
    writer = _writer(root)
    writer.add_episode(_frames(5, 0.0), "Lift the pot.")
    writer.add_episode(_frames(4, 10.0), "Put the pot down.")
    seen = load_with_lerobot(root)
    assert (seen["version"], seen["episodes"], seen["frames"], seen["fps"]) == ("v3.0", 2, 9, 20)
    assert seen["shapes"]["observation.state"] == [3]
    assert seen["shapes"]["observation.images.front"] == [3, 16, 24]  # CHW float in [0, 1]
    assert seen["tasks"] == ["Lift the pot.", "Put the pot down."]
    assert seen["episode_index"] == [0] * 5 + [1] * 4
    assert [s[0] for s in seen["state"]] == [0, 1, 2, 3, 4, 10, 11, 12, 13]
    # frame t of each episode is the grey level 20 t (H.264 moves it by a few levels)
    expected = [20 * t / 255 for t in (*range(5), *range(4))]
    assert seen["image_means"]["observation.images.wrist"] == pytest.approx(expected, abs=0.03)
