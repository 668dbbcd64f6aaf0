"""Write demonstrations as a LeRobot dataset (format v3.0), episode by episode, resumably.

The layout the current ``lerobot`` release's ``LeRobotDataset`` reads (so ACT, Diffusion
Policy, SmolVLA and pi0 training code can use the data)::

    meta/info.json                           features, fps, counts, path templates
    meta/tasks.parquet                       task_index per distinct instruction (the index)
    meta/stats.json                          min/max/mean/std/count/quantiles over all frames
    meta/episodes/chunk-000/file-000.parquet one row per episode: task, length, where its
                                             frames and video segments are, its own stats
    data/chunk-000/file-000.parquet          the frames of many episodes, one row per frame
    videos/<camera key>/chunk-000/file-000.mp4   many episodes' pictures, one after another

Each frame row holds ``observation.state`` (joint positions then gripper openings),
``observation.tcp_pose``, ``action``, ``timestamp``, ``frame_index``, ``episode_index``,
``index`` (global frame index) and ``task_index``. Images are not in the rows: each
camera ``observation.images.<name>`` is an H.264 MP4 holding episode after episode;
the episode's row says where its segment starts and ends (``from_timestamp``,
``to_timestamp``). A data file (a video file) takes episodes until it reaches
:data:`DATA_FILE_MB` (:data:`VIDEO_FILE_MB`); then the next file starts.

Crash safety: adding an episode writes every file it changes (the data and video
files it appends to, the episode, task and stats metadata, ``info.json``) under
``.staging/`` first; then a journal naming those files is written (atomically), the
files are moved into place, and the journal is removed. A writer that finds a journal
when it opens finishes the moves; one that finds staged files without a journal
discards them. The dataset is therefore always the one before or the one after an
episode, never a mixture.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

CODEBASE_VERSION = "v3.0"
CHUNKS_SIZE = 1000  # files per chunk folder
DATA_FILE_MB = 100  # a data file takes episodes up to this size
VIDEO_FILE_MB = 200  # a video file takes episodes up to this size
DATA_PATH = "data/chunk-{chunk_index:03d}/file-{file_index:03d}.parquet"
VIDEO_PATH = "videos/{video_key}/chunk-{chunk_index:03d}/file-{file_index:03d}.mp4"
EPISODES_PATH = "meta/episodes/chunk-000/file-000.parquet"
TASKS_PATH = "meta/tasks.parquet"
STATS_PATH = "meta/stats.json"
INFO_PATH = "meta/info.json"
STAGING = ".staging"
JOURNAL = ".staging/commit.json"
QUANTILES = (0.01, 0.10, 0.50, 0.90, 0.99)  # kept as q01 ... q99, as LeRobot keeps them


class DatasetMismatch(ValueError):
    """An existing dataset folder was made with other features, another fps or another
    format version."""


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
            "info": {"video.fps": _fps(fps), "video.height": height, "video.width": width,
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
        self._recover()
        info_path = self.root / INFO_PATH
        if info_path.exists():
            self.info = json.loads(info_path.read_text(encoding="utf-8"))
            self._check_same(features, fps)
            self.rows = self._read_episodes()
            self.tasks = self._read_tasks()
        else:
            (self.root / "meta").mkdir(parents=True, exist_ok=True)
            self.info = {
                "codebase_version": CODEBASE_VERSION, "robot_type": robot_type,
                "total_episodes": 0, "total_frames": 0, "total_tasks": 0,
                "chunks_size": CHUNKS_SIZE, "data_files_size_in_mb": DATA_FILE_MB,
                "video_files_size_in_mb": VIDEO_FILE_MB, "fps": _fps(fps), "splits": {},
                "data_path": DATA_PATH,
                "video_path": VIDEO_PATH if self._video_keys(features) else None,
                "features": features,
            }
            self.rows = []
            self.tasks = {}
            _write_json(info_path, self.info)

    # ------------------------------------------------------------------ public
    @property
    def episodes(self) -> int:
        return int(self.info["total_episodes"])

    def add_episode(self, frames: Sequence[Frame], task: str) -> int:
        """Write one episode; returns its index."""
        if not frames:
            raise ValueError("an episode needs at least one frame")
        index = self.episodes
        tasks = dict(self.tasks)
        task_index = tasks.setdefault(task, len(tasks))
        start = int(self.info["total_frames"])
        staged: list[str] = []
        row: dict[str, Any] = {"episode_index": index, "tasks": [task], "length": len(frames)}
        row.update(self._stage_data(frames, index, task_index, start, staged))
        for key in self._video_keys(self.info["features"]):
            camera = key.removeprefix("observation.images.")
            row.update(self._stage_video([f.images[camera] for f in frames], key, staged))
        stats = _stats(frames, index, task_index, self.fps, start)
        row.update({f"stats/{feature}/{name}": value for feature, block in stats.items()
                    for name, value in block.items()})
        row.update({"meta/episodes/chunk_index": 0, "meta/episodes/file_index": 0})
        rows = [*self.rows, row]
        self._stage_table(EPISODES_PATH, _episodes_table(rows), staged)
        self._stage_table(TASKS_PATH, _tasks_table(tasks), staged)
        _write_json(self._staged(STATS_PATH, staged), _aggregate([_row_stats(r) for r in rows]))
        info = dict(self.info)
        info.update(total_episodes=index + 1, total_frames=start + len(frames),
                    total_tasks=len(tasks), splits={"train": f"0:{index + 1}"})
        _write_json(self._staged(INFO_PATH, staged), info)  # last: the journal keeps the order
        self._commit(staged)
        self.info, self.rows, self.tasks = info, rows, tasks
        return index

    # ------------------------------------------------------------------ staging
    def _staged(self, relative: str, staged: list[str]) -> Path:
        """Where the new version of ``relative`` is written before the commit."""
        path = self.root / STAGING / relative
        path.parent.mkdir(parents=True, exist_ok=True)
        staged.append(relative)
        return path

    def _stage_table(self, relative: str, table: Any, staged: list[str]) -> None:
        import pyarrow.parquet as pq

        pq.write_table(table, self._staged(relative, staged))

    def _stage_data(self, frames: Sequence[Frame], index: int, task_index: int, start: int,
                    staged: list[str]) -> dict[str, Any]:
        import pyarrow as pa
        import pyarrow.parquet as pq

        n = len(frames)
        columns = {
            "observation.state": _vector_column(pa, [f.state for f in frames]),
            "observation.tcp_pose": _vector_column(pa, [f.tcp_pose for f in frames]),
            "action": _vector_column(pa, [f.action for f in frames]),
            "timestamp": pa.array(np.arange(n, dtype=np.float32) / np.float32(self.fps)),
            "frame_index": pa.array(np.arange(n, dtype=np.int64)),
            "episode_index": pa.array(np.full(n, index, dtype=np.int64)),
            "index": pa.array(np.arange(start, start + n, dtype=np.int64)),
            "task_index": pa.array(np.full(n, task_index, dtype=np.int64)),
        }
        table = pa.table(columns)
        chunk, file = self._place("data", None, DATA_FILE_MB)
        path = DATA_PATH.format(chunk_index=chunk, file_index=file)
        if (self.root / path).exists():
            table = pa.concat_tables([pq.read_table(self.root / path), table])
        self._stage_table(path, table, staged)
        return {"data/chunk_index": chunk, "data/file_index": file,
                "dataset_from_index": start, "dataset_to_index": start + n}

    def _stage_video(self, images: Sequence[NDArray[np.uint8]], key: str,
                     staged: list[str]) -> dict[str, Any]:
        chunk, file = self._place(f"videos/{key}", key, VIDEO_FILE_MB)
        relative = VIDEO_PATH.format(video_key=key, chunk_index=chunk, file_index=file)
        target = self._staged(relative, staged)
        existing = self.root / relative
        begin = 0.0
        if existing.exists():
            begin = float(self.rows[-1][f"videos/{key}/to_timestamp"])
            episode = target.with_name(target.stem + ".episode.mp4")
            _encode(images, episode, self.fps)
            _concatenate([existing, episode], target)
            episode.unlink()
        else:
            _encode(images, target, self.fps)
        return {f"videos/{key}/chunk_index": chunk, f"videos/{key}/file_index": file,
                f"videos/{key}/from_timestamp": begin,
                f"videos/{key}/to_timestamp": begin + len(images) / self.fps}

    def _place(self, prefix: str, key: str | None, limit_mb: float) -> tuple[int, int]:
        """The (chunk, file) the new episode goes to: the last episode's, unless that file
        has reached ``limit_mb``."""
        if not self.rows:
            return 0, 0
        last = self.rows[-1]
        chunk, file = int(last[f"{prefix}/chunk_index"]), int(last[f"{prefix}/file_index"])
        path = (VIDEO_PATH.format(video_key=key, chunk_index=chunk, file_index=file) if key
                else DATA_PATH.format(chunk_index=chunk, file_index=file))
        if (self.root / path).stat().st_size < limit_mb * 2**20:
            return chunk, file
        return (chunk + 1, 0) if file == CHUNKS_SIZE - 1 else (chunk, file + 1)

    # ------------------------------------------------------------------ commit, recovery
    def _commit(self, staged: list[str]) -> None:
        _write_json(self.root / JOURNAL, {"files": staged})
        self._finish(staged)

    def _finish(self, staged: list[str]) -> None:
        for relative in staged:
            source = self.root / STAGING / relative
            if source.exists():
                target = self.root / relative
                target.parent.mkdir(parents=True, exist_ok=True)
                os.replace(source, target)
        shutil.rmtree(self.root / STAGING)

    def _recover(self) -> None:
        """Finish a commit a crash interrupted; discard files staged for none."""
        journal = self.root / JOURNAL
        if journal.exists():
            self._finish(json.loads(journal.read_text(encoding="utf-8"))["files"])
        elif (self.root / STAGING).exists():
            shutil.rmtree(self.root / STAGING)

    # ------------------------------------------------------------------ reading back
    def _read_episodes(self) -> list[dict[str, Any]]:
        import pyarrow.parquet as pq

        path = self.root / EPISODES_PATH
        rows = pq.read_table(path).to_pylist() if path.exists() else []
        return [r for r in rows if r["episode_index"] < self.episodes]

    def _read_tasks(self) -> dict[str, int]:
        import pyarrow.parquet as pq

        path = self.root / TASKS_PATH
        if not path.exists():
            return {}
        return {r[_TASK_COLUMN]: int(r["task_index"]) for r in pq.read_table(path).to_pylist()}

    def _check_same(self, features: dict[str, Any], fps: float) -> None:
        version = self.info.get("codebase_version")
        if version != CODEBASE_VERSION:
            raise DatasetMismatch(
                f"{self.root}: a LeRobot dataset of format {version}, and fsvla writes "
                f"{CODEBASE_VERSION}; collect into a new folder (LeRobot's "
                "convert_dataset_v21_to_v30 script converts a v2.1 dataset)")
        if self.info["features"] != features or float(self.info["fps"]) != float(fps):
            differ = sorted(k for k in set(features) | set(self.info["features"])
                            if features.get(k) != self.info["features"].get(k))
            raise DatasetMismatch(
                f"{self.root} holds a dataset with other features or fps (differing: "
                f"{', '.join(differ) or 'fps'}); collect into a new folder")

    @staticmethod
    def _video_keys(features: Mapping[str, Any]) -> list[str]:
        return [k for k, v in features.items() if v["dtype"] == "video"]


# ---------------------------------------------------------------------- tables
#: The tasks table is a pandas frame indexed by the task text (LeRobot reads it with
#: ``pandas.read_parquet``); its index is stored as this column, described in the
#: ``pandas`` schema metadata as pandas' documented parquet layout has it.
_TASK_COLUMN = "__index_level_0__"


def _tasks_table(tasks: Mapping[str, int]) -> Any:
    import pyarrow as pa

    ordered = sorted(tasks, key=tasks.__getitem__)
    pandas = {
        "index_columns": [_TASK_COLUMN],
        "column_indexes": [{"name": None, "field_name": None, "pandas_type": "unicode",
                            "numpy_type": "object", "metadata": {"encoding": "UTF-8"}}],
        "columns": [
            {"name": "task_index", "field_name": "task_index", "pandas_type": "int64",
             "numpy_type": "int64", "metadata": None},
            {"name": None, "field_name": _TASK_COLUMN, "pandas_type": "unicode",
             "numpy_type": "object", "metadata": None}],
        "attributes": {}, "creator": {"library": "fsvla"}, "pandas_version": "2.0.0"}
    table = pa.table({"task_index": pa.array([tasks[t] for t in ordered], type=pa.int64()),
                      _TASK_COLUMN: pa.array(ordered, type=pa.string())})
    return table.replace_schema_metadata({"pandas": json.dumps(pandas)})


def _episodes_table(rows: Sequence[Mapping[str, Any]]) -> Any:
    import pyarrow as pa

    return pa.Table.from_pylist([dict(r) for r in rows])


def _vector_column(pa: Any, rows: Sequence[NDArray[np.float32]]) -> Any:
    values = np.stack([np.asarray(r, dtype=np.float32) for r in rows])
    return pa.FixedSizeListArray.from_arrays(pa.array(values.reshape(-1)), values.shape[1])


# ---------------------------------------------------------------------- statistics
def _stats(frames: Sequence[Frame], index: int, task_index: int, fps: float,
           start: int) -> dict[str, dict[str, Any]]:
    """Per-feature statistics of one episode, as LeRobot keeps them (images per channel,
    shaped (3, 1, 1), in [0, 1])."""
    n = len(frames)
    stats = {
        "observation.state": _numeric(np.stack([f.state for f in frames])),
        "observation.tcp_pose": _numeric(np.stack([f.tcp_pose for f in frames])),
        "action": _numeric(np.stack([f.action for f in frames])),
        "timestamp": _numeric(np.arange(n) / fps),
        "frame_index": _numeric(np.arange(n)),
        "episode_index": _numeric(np.full(n, index)),
        "index": _numeric(np.arange(start, start + n)),
        "task_index": _numeric(np.full(n, task_index)),
    }
    for camera in frames[0].images:
        pixels = np.stack([f.images[camera] for f in frames]).astype(np.float64) / 255.0
        block = _numeric(pixels.reshape(-1, 3))
        stats[f"observation.images.{camera}"] = {
            name: value if name == "count" else np.reshape(value, (3, 1, 1)).tolist()
            for name, value in block.items()} | {"count": [n]}
    return stats


def _numeric(values: NDArray[Any]) -> dict[str, Any]:
    values = values.reshape(len(values), -1).astype(np.float64)
    out = {"min": values.min(0).tolist(), "max": values.max(0).tolist(),
           "mean": values.mean(0).tolist(), "std": values.std(0).tolist(),
           "count": [len(values)]}
    for q in QUANTILES:
        out[f"q{round(q * 100):02d}"] = np.quantile(values, q, axis=0).tolist()
    return out


def _row_stats(row: Mapping[str, Any]) -> dict[str, dict[str, Any]]:
    stats: dict[str, dict[str, Any]] = {}
    for column, value in row.items():
        if column.startswith("stats/"):
            feature, _, name = column.removeprefix("stats/").rpartition("/")
            stats.setdefault(feature, {})[name] = value
    return stats


def _aggregate(episodes: Sequence[Mapping[str, Mapping[str, Any]]]) -> dict[str, Any]:
    """Dataset statistics from per-episode ones: count-weighted means, pooled variance,
    count-weighted quantiles (LeRobot's own aggregation)."""
    out: dict[str, Any] = {}
    for feature in episodes[0]:
        blocks = [e[feature] for e in episodes]
        counts = np.array([b["count"][0] for b in blocks], dtype=np.float64)
        total = counts.sum()

        def stack(name: str, blocks: Sequence[Mapping[str, Any]] = blocks) -> NDArray[np.float64]:
            return np.stack([np.asarray(b[name], dtype=np.float64) for b in blocks])

        weights = counts.reshape(-1, *([1] * (stack("mean").ndim - 1)))
        mean = (stack("mean") * weights).sum(0) / total
        variance = ((stack("std") ** 2 + (stack("mean") - mean) ** 2) * weights).sum(0) / total
        block = {"min": stack("min").min(0).tolist(), "max": stack("max").max(0).tolist(),
                 "mean": mean.tolist(), "std": np.sqrt(variance).tolist(), "count": [int(total)]}
        for name in blocks[0]:
            if name.startswith("q") and name[1:].isdigit():
                block[name] = ((stack(name) * weights).sum(0) / total).tolist()
        out[feature] = block
    return out


# ---------------------------------------------------------------------- files
def _encode(images: Sequence[NDArray[np.uint8]], path: Path, fps: float) -> None:
    """An H.264 MP4 of ``images``, a keyframe every other frame (as LeRobot encodes, so a
    trainer can seek to any frame cheaply) and no B-frames."""
    import imageio.v2 as imageio

    writer = imageio.get_writer(path, format="FFMPEG", fps=fps, codec="libx264",  # type: ignore[arg-type]
                                pixelformat="yuv420p", macro_block_size=1,
                                ffmpeg_log_level="error", output_params=["-g", "2", "-bf", "0"])
    try:
        for image in images:
            writer.append_data(np.ascontiguousarray(image))
    finally:
        writer.close()


def _concatenate(parts: Sequence[Path], out: Path) -> None:
    """``parts`` one after another in ``out``, without re-encoding (FFmpeg's concat demuxer,
    with the FFmpeg that imageio-ffmpeg ships)."""
    import imageio_ffmpeg

    listing = out.with_name(out.stem + ".parts.txt")
    listing.write_text("".join(f"file '{p.resolve()}'\n" for p in parts), encoding="utf-8")
    try:
        done = subprocess.run([imageio_ffmpeg.get_ffmpeg_exe(), "-y", "-loglevel", "error",
                               "-f", "concat", "-safe", "0", "-i", str(listing), "-c", "copy",
                               "-movflags", "+faststart", str(out)],
                              capture_output=True, text=True, check=False)
    finally:
        listing.unlink()
    if done.returncode != 0:
        raise RuntimeError(f"FFmpeg could not join the videos into {out}: {done.stderr.strip()}")


def _write_json(path: Path, data: Any) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    temporary = path.with_name(path.name + ".tmp")
    temporary.write_text(json.dumps(data, indent=2), encoding="utf-8")
    os.replace(temporary, path)


def _fps(fps: float) -> float | int:
    """LeRobot states fps as an integer; keep one where it is one."""
    return int(fps) if float(fps).is_integer() else fps


__all__ = ["CODEBASE_VERSION", "DatasetMismatch", "Frame", "LeRobotWriter", "features"]
