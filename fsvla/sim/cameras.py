"""Which cameras a scene renders, at what resolution: the ``--cameras`` and
``--resolution`` of a run, applied to a SceneSpec's cameras before it is built.

Imports no simulator (the run options are checked before anything is built).
"""

from __future__ import annotations

import difflib
import re
from collections.abc import Sequence

import numpy as np

from fsvla.compiler.scene import SceneCamera

#: The largest side a camera may have (pixels): beyond this is a typo, not a benchmark.
MAX_RESOLUTION = 4096


def parse_resolution(text: str | Sequence[int]) -> tuple[int, int]:
    """``"160x120"`` (or ``(160, 120)``) as (width, height); ValueError otherwise."""
    if isinstance(text, str):
        match = re.fullmatch(r"\s*(\d+)\s*[xX×]\s*(\d+)\s*", text)
        if match is None:
            raise ValueError(f"resolution must be WIDTHxHEIGHT in pixels (e.g. 160x120), "
                             f"got {text!r}")
        width, height = int(match[1]), int(match[2])
    else:
        values = tuple(text)
        if len(values) != 2 or not all(isinstance(v, (int, np.integer)) for v in values):
            raise ValueError(f"resolution must be (width, height) in pixels, got {text!r}")
        width, height = int(values[0]), int(values[1])
    if not (1 <= width <= MAX_RESOLUTION and 1 <= height <= MAX_RESOLUTION):
        raise ValueError(f"resolution {width}x{height} is outside 1..{MAX_RESOLUTION} pixels "
                         "a side")
    return width, height


def check_camera_names(names: Sequence[str], known: Sequence[str]) -> tuple[str, ...]:
    """``names`` (in their order, without repeats) if every one is a camera in ``known``;
    otherwise a ValueError naming the unknown one, with the closest camera."""
    chosen = tuple(dict.fromkeys(n.strip() for n in names if n.strip()))
    if not chosen:
        raise ValueError(f"name at least one camera; cameras: {', '.join(known) or 'none'}")
    for name in chosen:
        if name not in known:
            close = difflib.get_close_matches(name, known, n=1)
            hint = f"; did you mean {close[0]!r}?" if close else ""
            raise ValueError(f"unknown camera {name!r}{hint} (cameras: "
                             f"{', '.join(known) or 'none'})")
    return chosen


def camera_selection(cameras: Sequence[SceneCamera], names: Sequence[str] | None = None,
                     resolution: tuple[int, int] | None = None) -> tuple[SceneCamera, ...]:
    """The cameras ``names`` picks from ``cameras`` (all when None), in the scene's order,
    each at ``resolution`` (width, height; its own when None). The vertical field of view
    stays; the horizontal one follows the new aspect ratio."""
    if names is not None:
        chosen = set(check_camera_names(names, [c.name for c in cameras]))
        cameras = [c for c in cameras if c.name in chosen]
    if resolution is not None:
        width, height = resolution
        cameras = [c.model_copy(update={"width": width, "height": height}) for c in cameras]
    return tuple(cameras)


__all__ = ["MAX_RESOLUTION", "camera_selection", "check_camera_names", "parse_resolution"]
