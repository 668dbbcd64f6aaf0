"""bench/baseline.py end to end with a tiny budget: two demonstrations of one scenario,
two training steps, one evaluated episode. It runs in an interpreter that has LeRobot
and fsvla (tests/collect/lerobot_loader.py finds it: skipped without one, a failure under
CI with ``FSVLA_REQUIRE_LEROBOT=1``)."""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.sim
@pytest.mark.render
@pytest.mark.slow  # about three minutes: two rendered demonstrations, torch, one episode
def test_the_baseline_collects_trains_and_evaluates(tmp_path: Path, render_device) -> None:
    from tests.collect.lerobot_loader import lerobot_python

    python = lerobot_python()
    out = tmp_path / "baseline"
    command = [python, str(ROOT / "bench" / "baseline.py"), "--out", str(out),
               "--scenarios", "place_glass_on_shelf", "--episodes", "2", "--train-steps", "2",
               "--save-every", "2", "--device", "cpu", "--workers", "0", "--cells", "L0"]
    done = subprocess.run(command, capture_output=True, text=True, timeout=900, check=False,
                          env={**os.environ, "HF_HUB_OFFLINE": "1"})
    assert done.returncode == 0, (done.stdout + done.stderr)[-4000:]

    summary = json.loads((out / "baseline.json").read_text())
    assert summary["datasets"]["panda"]["episodes"] == 2
    info = json.loads((out / "data/fsvla/place_glass_on_shelf/meta/info.json").read_text())
    images = [k for k, v in info["features"].items() if v["dtype"] == "video"]
    assert images == ["observation.images.front"]  # fsvla collect --cameras front
    assert info["features"][images[0]]["shape"] == [96, 128, 3]  # --resolution 128x96
    (trained,) = summary["training"].values()
    assert trained["steps"] == 2 and trained["parameters"] > 0
    assert (Path(trained["checkpoint"]) / "model.safetensors").is_file()
    (cell,) = summary["per_cell"]
    assert cell["cell"] == "L0/W0/V0" and cell["n"] == 1 and cell["faults"] == 0
    assert sum(cell[q] for q in ("SS", "US", "SF", "UF")) == pytest.approx(1.0)

    # Run again: every stage is found done and skipped but the evaluation's report.
    again = subprocess.run(command, capture_output=True, text=True, timeout=600, check=False,
                           env={**os.environ, "HF_HUB_OFFLINE": "1"})
    assert again.returncode == 0, again.stderr[-4000:]
    assert "fsvla collect" not in again.stdout and "lerobot-train" not in again.stdout
