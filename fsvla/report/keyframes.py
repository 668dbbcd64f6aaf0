"""Keyframes of an episode from a recorded video, when the run folder has one.

Where a run keeps an episode's pictures (either one):

* ``<run>/videos/<episode_id>.{mp4,webm,mkv,avi,gif}``: a video, one frame per control
  step or any other rate (frames are mapped to steps proportionally);
* ``<run>/frames/<episode_id>/*.{png,jpg,jpeg}``: one image per frame, in name order.

Four frames, evenly spaced from the first to the last, become the keyframes of Fig. 5.
GIFs and image folders are read with Pillow (which matplotlib brings); other videos with
OpenCV when it is installed. A run without pictures is normal: the report then says so.
"""

from __future__ import annotations

import io
from pathlib import Path
from typing import Any

from pydantic import BaseModel, ConfigDict, Field

VIDEO_SUFFIXES = (".mp4", ".webm", ".mkv", ".avi", ".gif")
IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg")
KEYFRAMES = 4
MAX_WIDTH = 480


class Keyframe(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)

    frame: int  # 0-based index in the video
    step: int | None  # the control step it shows (1-based), when the steps are known
    png: bytes = Field(exclude=True, repr=False)


class Keyframes(BaseModel):
    """The keyframes found, or a note saying why there are none."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    source: str | None  # the video or folder, relative to the run folder
    note: str
    frames: tuple[Keyframe, ...] = ()


def find_video(run_dir: Path, episode_id: str) -> Path | None:
    """The episode's video file or frame folder, if the run recorded one."""
    for suffix in VIDEO_SUFFIXES:
        path = run_dir / "videos" / f"{episode_id}{suffix}"
        if path.is_file():
            return path
    folder = run_dir / "frames" / episode_id
    return folder if folder.is_dir() else None


def _png(image: Any) -> bytes:
    from PIL import Image

    picture = image if isinstance(image, Image.Image) else Image.fromarray(image)
    picture = picture.convert("RGB")
    if picture.width > MAX_WIDTH:
        picture = picture.resize((MAX_WIDTH, round(picture.height * MAX_WIDTH / picture.width)))
    buffer = io.BytesIO()
    picture.save(buffer, format="PNG")
    return buffer.getvalue()


def _pick(count: int, wanted: int = KEYFRAMES) -> list[int]:
    if count <= wanted:
        return list(range(count))
    return sorted({round(i * (count - 1) / (wanted - 1)) for i in range(wanted)})


def _read_folder(folder: Path) -> tuple[int, dict[int, bytes]]:
    from PIL import Image

    files = sorted(p for p in folder.iterdir() if p.suffix.lower() in IMAGE_SUFFIXES)
    chosen = _pick(len(files))
    frames = {}
    for i in chosen:
        with Image.open(files[i]) as image:
            frames[i] = _png(image)
    return len(files), frames


def _read_gif(path: Path) -> tuple[int, dict[int, bytes]]:
    from PIL import Image, ImageSequence

    with Image.open(path) as image:
        count = getattr(image, "n_frames", 1)
        chosen = set(_pick(count))
        frames = {i: _png(f.copy()) for i, f in enumerate(ImageSequence.Iterator(image))
                  if i in chosen}
    return count, frames


def _read_video(path: Path) -> tuple[int, dict[int, bytes]]:
    import cv2  # optional: opencv-python(-headless)

    capture = cv2.VideoCapture(str(path))
    try:
        if not capture.isOpened():
            raise OSError(f"OpenCV cannot open {path.name}")
        count = int(capture.get(cv2.CAP_PROP_FRAME_COUNT))
        frames = {}
        for i in _pick(count):
            capture.set(cv2.CAP_PROP_POS_FRAMES, i)
            ok, bgr = capture.read()
            if ok:
                frames[i] = _png(cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB))
    finally:
        capture.release()
    return count, frames


def load_keyframes(run_dir: Path, episode_id: str, steps: int | None = None) -> Keyframes:
    """The episode's keyframes (see the module doc); never raises for a missing video."""
    path = find_video(run_dir, episode_id)
    if path is None:
        return Keyframes(source=None, note=(
            f"This run recorded no video of {episode_id} (looked for "
            f"videos/{episode_id}.{{{','.join(s[1:] for s in VIDEO_SUFFIXES)}}} and "
            f"frames/{episode_id}/ in the run folder): no keyframes."))
    source = str(path.relative_to(run_dir))
    try:
        if path.is_dir():
            count, frames = _read_folder(path)
        elif path.suffix == ".gif":
            count, frames = _read_gif(path)
        else:
            count, frames = _read_video(path)
    except ImportError:
        return Keyframes(source=source, note=(
            f"{source} needs OpenCV to read: pip install opencv-python-headless"))
    except (OSError, ValueError) as err:
        return Keyframes(source=source, note=f"{source} could not be read: {err}")
    if not frames:
        return Keyframes(source=source, note=f"{source} holds no readable frame.")

    def step_of(i: int) -> int | None:
        if not steps:
            return None
        return min(steps, max(1, round((i + 1) * steps / count)))

    keyframes = tuple(Keyframe(frame=i, step=step_of(i), png=png) for i, png in frames.items())
    return Keyframes(source=source, frames=keyframes,
                     note=f"{len(keyframes)} keyframes of {count} frames in {source}.")


__all__ = ["Keyframe", "Keyframes", "find_video", "load_keyframes"]
