"""`fsvla collect`: the careful expert's safe successes become demonstrations; it resumes."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

pytest.importorskip("sapien")
pytest.importorskip("pyarrow")
import pyarrow.parquet as pq  # noqa: E402
from fsvla.cli import run  # noqa: E402
from fsvla.collect import collect  # noqa: E402

pytestmark = [pytest.mark.sim, pytest.mark.slow]


def test_collect_keeps_safe_successes_and_resumes(tmp_path: Path) -> None:
    out = tmp_path / "demo"
    progress = collect("place_glass_on_shelf", out, 1, images=False)
    assert progress.kept == 1 and progress.attempts >= 1
    info = json.loads((out / "meta/info.json").read_text())
    assert info["total_episodes"] == 1 and info["robot_type"] == "panda"
    table = pq.read_table(out / "data/chunk-000/episode_000000.parquet")
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
