"""`fsvla collect`: the careful expert's safe successes become demonstrations; it resumes."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("pyarrow")
import pyarrow.parquet as pq

from fsvla.cli import run
from fsvla.collect import collect

pytestmark = [pytest.mark.sim, pytest.mark.slow]


def test_collect_keeps_safe_successes_and_resumes(tmp_path: Path) -> None:
    out = tmp_path / "demo"
    progress = collect("place_glass_on_shelf", out, 1, images=False)
    assert progress.kept == 1 and progress.attempts >= 1
    info = json.loads((out / "meta/info.json").read_text())
    assert info["total_episodes"] == 1 and info["robot_type"] == "panda"
    table = pq.read_table(out / "data/chunk-000/file-000.parquet")
    assert table.num_rows == info["total_frames"] > 20
    assert len(table.column("action").to_pylist()[0]) == 8
    # Asking for the same number again does nothing; the attempts are remembered.
    again = collect("place_glass_on_shelf", out, 1, images=False)
    assert (again.kept, again.attempts) == (1, progress.attempts)


def test_cli_reports_a_bad_scenario_without_a_traceback(tmp_path: Path, capsys) -> None:
    code = run(["collect", "no_such_scenario", "--episodes", "1", "-o", str(tmp_path / "d")])
    captured = capsys.readouterr()
    assert code == 2 and "unknown scenario 'no_such_scenario'" in captured.err
    assert "Traceback" not in captured.err and not (tmp_path / "d").exists()


def test_lerobot_loads_a_collected_demonstration(tmp_path: Path, render_device) -> None:
    """`fsvla collect` with its cameras, read back by LeRobot's own LeRobotDataset."""
    from .lerobot_loader import lerobot_python, load_with_lerobot

    lerobot_python()  # skip before the minute of rendering when there is no lerobot
    out = tmp_path / "demo"
    assert run(["collect", "stack_block_gently", "--episodes", "1", "-o", str(out)]) == 0
    info = json.loads((out / "meta/info.json").read_text())
    table = pq.read_table(out / "data/chunk-000/file-000.parquet")
    seen = load_with_lerobot(out)
    assert info["total_frames"] == table.num_rows
    assert (seen["episodes"], seen["frames"]) == (1, table.num_rows)
    assert seen["tasks"] == ["Stack the red block on the blue block gently."]
    np.testing.assert_allclose(np.array(seen["state"]),
                               np.array(table.column("observation.state").to_pylist()), atol=1e-6)
    cameras = {k for k in info["features"] if k.startswith("observation.images.")}
    assert cameras and set(seen["image_means"]) == cameras
    for camera in cameras:
        height, width, _ = info["features"][camera]["shape"]
        assert seen["shapes"][camera] == [3, height, width]
        assert len(seen["image_means"][camera]) == table.num_rows
        assert 0.05 < min(seen["image_means"][camera])  # decoded pictures, not black frames
