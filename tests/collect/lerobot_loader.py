"""Open a dataset with the ``lerobot`` package's own ``LeRobotDataset`` class.

LeRobot pulls in torch (gigabytes), so it is not a dependency of fsvla's test extra: it
lives in the interpreter named by ``FSVLA_LEROBOT_PYTHON`` (``.ci/run`` builds one with
the current lerobot release, which reads the v3.0 format fsvla writes) or in this one. The
loading runs in that interpreter as a subprocess and answers with JSON. Without either
the tests skip, unless ``FSVLA_REQUIRE_LEROBOT=1`` (set by CI) turns that into a failure.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

# Reads every frame (decoding the videos with PyAV) and reports what a trainer would see.
_PROBE = r"""
import json, os, sys
os.environ["HF_HUB_OFFLINE"] = "1"
from lerobot.datasets.lerobot_dataset import LeRobotDataset
ds = LeRobotDataset("local/fsvla", root=sys.argv[1], video_backend="pyav")
frames = [ds[i] for i in range(len(ds))]
def shape(v):
    return list(v.shape) if hasattr(v, "shape") else None
print(json.dumps({
    "version": ds.meta.info["codebase_version"],
    "episodes": ds.num_episodes, "frames": ds.num_frames, "fps": ds.fps,
    "shapes": {k: shape(v) for k, v in frames[0].items()},
    "tasks": sorted({f["task"] for f in frames}),
    "state": [f["observation.state"].tolist() for f in frames],
    "episode_index": [int(f["episode_index"]) for f in frames],
    "image_means": {k: [float(f[k].float().mean()) for f in frames]
                    for k in frames[0] if k.startswith("observation.images.")},
}))
"""


def lerobot_python() -> str:
    """An interpreter that has lerobot; skips (or fails under CI) when there is none."""
    try:
        import lerobot.datasets.lerobot_dataset  # noqa: F401
    except ImportError:
        pass
    else:
        return sys.executable
    named = os.environ.get("FSVLA_LEROBOT_PYTHON")
    if named and Path(named).exists():
        return named
    why = ("lerobot is not installed here and FSVLA_LEROBOT_PYTHON names no interpreter "
           "(.ci/run builds one: see its lerobot step)")
    if os.environ.get("FSVLA_REQUIRE_LEROBOT") == "1":
        pytest.fail(why)
    pytest.skip(why)


def load_with_lerobot(root: Path) -> dict[str, Any]:
    """What ``LeRobotDataset`` reads from the dataset at ``root``."""
    done = subprocess.run([lerobot_python(), "-c", _PROBE, str(root)], capture_output=True,
                          text=True, timeout=600, check=False)
    assert done.returncode == 0, f"LeRobotDataset could not load {root}:\n{done.stderr[-3000:]}"
    return json.loads(done.stdout.strip().splitlines()[-1])
