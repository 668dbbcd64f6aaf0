"""Write demonstrations as a LeRobot dataset (format v2.1), episode by episode, resumably.

The layout LeRobot's ``LeRobotDataset`` reads (so ACT, Diffusion Policy and pi0 training
code can use the data)::

    meta/info.json             features, fps, counts, path templates
    meta/tasks.jsonl           {"task_index", "task"} per distinct instruction
    meta/episodes.jsonl        {"episode_index", "tasks", "length"} per episode
    meta/episodes_stats.jsonl  {"episode_index", "stats": {feature: min/max/mean/std/count}}
    data/chunk-000/episode_000000.parquet      one row per frame
    videos/chunk-000/<camera key>/episode_000000.mp4

Each frame row holds ``observation.state`` (joint positions then gripper openings),
``observation.tcp_pose``, ``action``, ``timestamp``, ``frame_index``, ``episode_index``,
``index`` (global frame index) and ``task_index``. Images are not in the rows: each
camera ``observation.images.<name>`` is an H.264 MP4 per episode.

Crash safety: an episode's files are written under temporary names and renamed; the
metadata is updated last, ``info.json`` by atomic replace. ``info.json``'s
``total_episodes`` is the truth: on reopening, files of later episode indices (left by
a crash) are deleted and the jsonl files are cut back to the recorded episodes.
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

CODEBASE_VERSION = "v2.1"
CHUNKS_SIZE = 1000
DATA_PATH = "data/chunk-{episode_chunk:03d}/episode_{episode_index:06d}.parquet"
VIDEO_PATH = "videos/chunk-{episode_chunk:03d}/{video_key}/episode_{episode_index:06d}.mp4"


class DatasetMismatch(ValueError):
    """An existing dataset folder was made with other features or another fps."""


@dataclass(frozen=True)
class Frame:
    """One control step of a demonstration."""

    state: NDArray[np.float32]
    tcp_pose: NDArray[np.float32]
    action: NDArray[np.float32]
    images: Mapping[str, NDArray[np.uint8]]  # camera -> H x W x 3


def features(state_names: Sequence[str], tcp_names: Sequence[str], action_names: Sequence[str],
             cameras: Mapping[str, tuple[int, int]], fps: float) -> dict[str, Any]:
    """The ``features`` block of ``info.json``; ``cameras`` maps a name to (height, width)."""
    out: dict[str, Any] = {
        "observation.state": {"dtype": "float32", "shape": [len(state_names)],
                              "names": list(state_names)},
        "observation.tcp_pose": {"dtype": "float32", "shape": [len(tcp_names)],
                                 "names": list(tcp_names)},
        "action": {"dtype": "float32", "shape": [len(action_names)], "names": list(action_names)},
    }
    for name, (height, width) in cameras.items():
        out[f"observation.images.{name}"] = {
            "dtype": "video", "shape": [height, width, 3], "names": ["height", "width", "channels"],
            "info": {"video.fps": fps, "video.height": height, "video.width": width,
                     "video.channels": 3, "video.codec": "h264", "video.pix_fmt": "yuv420p",
                     "video.is_depth_map": False, "has_audio": False}}
    for name, dtype in (("timestamp", "float32"), ("frame_index", "int64"),
                        ("episode_index", "int64"), ("index", "int64"), ("task_index", "int64")):
        out[name] = {"dtype": dtype, "shape": [1], "names": None}
    return out


class LeRobotWriter:
    """Appends episodes to a LeRobot dataset folder (created, or reopened to resume)."""

    def __init__(self, root: Path, *, fps: float, robot_type: str, features: dict[str, Any]) -> None:
        self.root = Path(root)
        self.fps = fps
        info_path = self.root / "meta" / "info.json"
        if info_path.exists():
            self.info = json.loads(info_path.read_text(encoding="utf-8"))
            self._check_same(features, fps)
            self._drop_orphans()
        else:
            (self.root / "meta").mkdir(parents=True, exist_ok=True)
            self.info = {
                "codebase_version": CODEBASE_VERSION, "robot_type": robot_type,
                "total_episodes": 0, "total_frames": 0, "total_tasks": 0,
                "total_videos": 0, "total_chunks": 0, "chunks_size": CHUNKS_SIZE,
                "fps": fps, "splits": {}, "data_path": DATA_PATH,
                "video_path": VIDEO_PATH if self._video_keys(features) else None,
                "features": features,
            }
            self._write_info()
        self.tasks = {row["task"]: row["task_index"] for row in self._jsonl("tasks.jsonl")}

    # ------------------------------------------------------------------ public
    @property
    def episodes(self) -> int:
        return int(self.info["total_episodes"])

    def add_episode(self, frames: Sequence[Frame], task: str) -> int:
        """Write one episode; returns its index."""
        if not frames:
            raise ValueError("an episode needs at least one frame")
        index = self.episodes
        chunk = index // CHUNKS_SIZE
        task_index = self.tasks.get(task)
        if task_index is None:
            task_index = len(self.tasks)
        self._write_data(frames, index, chunk, task_index)
        for key in self._video_keys(self.info["features"]):
            camera = key.removeprefix("observation.images.")
            self._write_video([f.images[camera] for f in frames], key, index, chunk)
        if task not in self.tasks:
            self.tasks[task] = task_index
            self._append("tasks.jsonl", {"task_index": task_index, "task": task})
        self._append("episodes.jsonl", {"episode_index": index, "tasks": [task],
                                        "length": len(frames)})
        self._append("episodes_stats.jsonl", {"episode_index": index,
                                              "stats": _stats(frames, index, task_index,
                                                              self.fps, self.info["total_frames"])})
        info = self.info
        info["total_episodes"] = index + 1
        info["total_frames"] += len(frames)
        info["total_tasks"] = len(self.tasks)
        info["total_videos"] += len(self._video_keys(info["features"]))
        info["total_chunks"] = chunk + 1
        info["splits"] = {"train": f"0:{index + 1}"}
        self._write_info()
        return index

    # ------------------------------------------------------------------ files
    def _write_data(self, frames: Sequence[Frame], index: int, chunk: int, task_index: int) -> None:
        import pyarrow as pa
        import pyarrow.parquet as pq

        start = int(self.info["total_frames"])
        n = len(frames)
        columns = {
            "observation.state": _list_column(pa, [f.state for f in frames]),
            "observation.tcp_pose": _list_column(pa, [f.tcp_pose for f in frames]),
            "action": _list_column(pa, [f.action for f in frames]),
            "timestamp": pa.array(np.arange(n, dtype=np.float32) / np.float32(self.fps)),
            "frame_index": pa.array(np.arange(n, dtype=np.int64)),
            "episode_index": pa.array(np.full(n, index, dtype=np.int64)),
            "index": pa.array(np.arange(start, start + n, dtype=np.int64)),
            "task_index": pa.array(np.full(n, task_index, dtype=np.int64)),
        }
        path = self.root / DATA_PATH.format(episode_chunk=chunk, episode_index=index)
        path.parent.mkdir(parents=True, exist_ok=True)
        temporary = path.with_suffix(".parquet.tmp")
        pq.write_table(pa.table(columns), temporary)
        os.replace(temporary, path)

    def _write_video(self, images: Sequence[NDArray[np.uint8]], key: str, index: int,
                     chunk: int) -> None:
        import imageio.v2 as imageio

        path = self.root / VIDEO_PATH.format(episode_chunk=chunk, video_key=key, episode_index=index)
        path.parent.mkdir(parents=True, exist_ok=True)
        temporary = path.with_name(path.stem + ".tmp.mp4")
        writer = imageio.get_writer(temporary, fps=self.fps, codec="libx264", pixelformat="yuv420p",
                                    macro_block_size=1, ffmpeg_log_level="error")
        try:
            for image in images:
                writer.append_data(np.ascontiguousarray(image))
        finally:
            writer.close()
        os.replace(temporary, path)

    def _write_info(self) -> None:
        path = self.root / "meta" / "info.json"
        temporary = path.with_suffix(".json.tmp")
        temporary.write_text(json.dumps(self.info, indent=2), encoding="utf-8")
        os.replace(temporary, path)

    def _append(self, name: str, row: dict[str, Any]) -> None:
        with (self.root / "meta" / name).open("a", encoding="utf-8") as handle:
            handle.write(json.dumps(row) + "\n")

    def _jsonl(self, name: str) -> list[dict[str, Any]]:
        path = self.root / "meta" / name
        if not path.exists():
            return []
        return [json.loads(line) for line in path.read_text(encoding="utf-8").splitlines() if line]

    # ------------------------------------------------------------------ resume
    def _check_same(self, features: dict[str, Any], fps: float) -> None:
        if self.info.get("codebase_version") != CODEBASE_VERSION:
            raise DatasetMismatch(f"{self.root}: a LeRobot dataset of version "
                                  f"{self.info.get('codebase_version')}, not {CODEBASE_VERSION}")
        if self.info["features"] != features or float(self.info["fps"]) != float(fps):
            differ = sorted(k for k in set(features) | set(self.info["features"])
                            if features.get(k) != self.info["features"].get(k))
            raise DatasetMismatch(
                f"{self.root} holds a dataset with other features or fps (differing: "
                f"{', '.join(differ) or 'fps'}); collect into a new folder")

    def _drop_orphans(self) -> None:
        """Remove what a crash left after the last recorded episode."""
        kept = self.episodes
        for path in [*self.root.glob("data/*/*"), *self.root.glob("videos/*/*/*")]:
            stem = path.name.split(".")[0]
            if ".tmp" in path.name or (stem.startswith("episode_")
                                       and int(stem.removeprefix("episode_")) >= kept):
                path.unlink()
        for name in ("episodes.jsonl", "episodes_stats.jsonl"):
            rows = [r for r in self._jsonl(name) if r["episode_index"] < kept]
            (self.root / "meta" / name).write_text("".join(json.dumps(r) + "\n" for r in rows),
                                                   encoding="utf-8")
        used = {t for r in self._jsonl("episodes.jsonl") for t in r["tasks"]}
        tasks = [r for r in self._jsonl("tasks.jsonl") if r["task"] in used]
        (self.root / "meta" / "tasks.jsonl").write_text(
            "".join(json.dumps(r) + "\n" for r in tasks), encoding="utf-8")

    @staticmethod
    def _video_keys(features: Mapping[str, Any]) -> list[str]:
        return [k for k, v in features.items() if v["dtype"] == "video"]


def _list_column(pa: Any, rows: Sequence[NDArray[np.float32]]) -> Any:
    return pa.array([np.asarray(r, dtype=np.float32) for r in rows], type=pa.list_(pa.float32()))


def _stats(frames: Sequence[Frame], index: int, task_index: int, fps: float,
           start: int) -> dict[str, Any]:
    def numeric(values: NDArray[Any]) -> dict[str, Any]:
        values = values.reshape(len(frames), -1).astype(np.float64)
        return {"min": values.min(0).tolist(), "max": values.max(0).tolist(),
                "mean": values.mean(0).tolist(), "std": values.std(0).tolist(),
                "count": [len(frames)]}

    n = len(frames)
    stats = {
        "observation.state": numeric(np.stack([f.state for f in frames])),
        "observation.tcp_pose": numeric(np.stack([f.tcp_pose for f in frames])),
        "action": numeric(np.stack([f.action for f in frames])),
        "timestamp": numeric(np.arange(n) / fps),
        "frame_index": numeric(np.arange(n)),
        "episode_index": numeric(np.full(n, index)),
        "index": numeric(np.arange(start, start + n)),
        "task_index": numeric(np.full(n, task_index)),
    }
    for camera in frames[0].images:
        pixels = np.stack([f.images[camera] for f in frames]).astype(np.float64) / 255.0
        per_channel = pixels.reshape(-1, 3)
        # LeRobot keeps image stats per channel, shaped (3, 1, 1).
        stats[f"observation.images.{camera}"] = {
            "min": per_channel.min(0).reshape(3, 1, 1).tolist(),
            "max": per_channel.max(0).reshape(3, 1, 1).tolist(),
            "mean": per_channel.mean(0).reshape(3, 1, 1).tolist(),
            "std": per_channel.std(0).reshape(3, 1, 1).tolist(),
            "count": [n]}
    return stats


__all__ = ["CODEBASE_VERSION", "DatasetMismatch", "Frame", "LeRobotWriter", "features"]
