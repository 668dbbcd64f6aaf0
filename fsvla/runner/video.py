"""Pictures of a replayed episode: an MP4 through imageio-ffmpeg, else PNG frames.

``imageio`` and ``imageio-ffmpeg`` (which ships its own ffmpeg binary) are optional;
without them, or when encoding fails, the frames are written as numbered PNG files
into a folder next to the requested file (Pillow is always there), and the note says so.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

#: Frame sizes are padded to a multiple of this (what H.264 encoders want).
MACRO_BLOCK = 16


def tile(images: Mapping[str, NDArray[np.uint8]]) -> NDArray[np.uint8]:
    """The cameras' pictures side by side (shorter ones padded below, black)."""
    pictures = list(images.values())
    height = max(p.shape[0] for p in pictures)
    padded = [np.pad(p, ((0, height - p.shape[0]), (0, 0), (0, 0))) for p in pictures]
    return np.concatenate(padded, axis=1)


def write_video(frames: Sequence[NDArray[np.uint8]], path: Path, fps: float) -> tuple[Path, str]:
    """Write ``frames`` to ``path`` (an MP4 or any format imageio knows by the suffix);
    returns what was written and a note for the user."""
    path.parent.mkdir(parents=True, exist_ok=True)
    try:
        import imageio.v2 as imageio
        import imageio_ffmpeg  # noqa: F401 - the MP4 writer's ffmpeg
    except ImportError:
        folder = write_frames(frames, path)
        return folder, (f"imageio-ffmpeg is not installed, so no {path.suffix or 'video'} file: "
                        f"wrote {len(frames)} PNG frames to {folder} "
                        "(pip install imageio imageio-ffmpeg for MP4)")
    try:
        imageio.mimsave(path, [_even(f) for f in frames], fps=fps, macro_block_size=1)
    except Exception as err:  # noqa: BLE001 - an encoder problem: fall back to frames
        path.unlink(missing_ok=True)
        folder = write_frames(frames, path)
        return folder, (f"encoding {path} failed ({type(err).__name__}: {err}): wrote "
                        f"{len(frames)} PNG frames to {folder}")
    return path, f"wrote {path} ({len(frames)} frames at {fps:g} fps)"


def write_frames(frames: Sequence[NDArray[np.uint8]], path: Path) -> Path:
    """Numbered PNG files in ``<path without suffix>_frames/``; returns the folder."""
    from PIL import Image

    folder = path.with_name(f"{path.stem}_frames")
    folder.mkdir(parents=True, exist_ok=True)
    for index, frame in enumerate(frames):
        Image.fromarray(frame).save(folder / f"frame_{index:05d}.png")
    return folder


def _even(frame: NDArray[np.uint8]) -> NDArray[np.uint8]:
    height, width = frame.shape[:2]
    return np.pad(frame, ((0, -height % MACRO_BLOCK), (0, -width % MACRO_BLOCK), (0, 0)))


__all__ = ["tile", "write_frames", "write_video"]
